"""Turn a volpt scene file (Mitsuba XML, 0.5/0.6 or 3 spelling) into one that Mitsuba 3 renders with
the estimator volpt uses. Everything this changes is listed in the returned notes.

For every scene:
  * integrator: must be `volpath` or `volpathmis` (spectral MIS, for chromatic media); `rr_depth <= 0` (volpt: "no Russian roulette") becomes 10^9, since
    Mitsuba 3 rejects `rr_depth` values below 1; `max_depth` is kept (-1 = unlimited in both).
  * sampler: must be `independent` (anything else is an error: volpt only has that one).
  * `filename` strings are made absolute (after filling `$name` parameters), so that the written
    file can live anywhere.

Mitsuba 0.5/0.6 spelling (`version` < 2), converted to Mitsuba 3:
  * version -> 3.0.0; camelCase property names -> snake_case (maxDepth, rrDepth, toWorld,
    sampleCount, intIOR, extIOR, sigmaT, fovAxis, ...); `<lookAt>` -> `<lookat>`.
  * `<spectrum>`/`<srgb>` with one or three numbers -> `<rgb>` (rgb variants).
  * heterogeneous medium: `density` volume -> `sigma_t`; `method` (woodcock/simpson) dropped: Mitsuba 3
    always tracks with a majorant, which is what volpt does.
  * gridvolume: Mitsuba 0.6 puts sample i at min + i/(n-1) * extent (vertex-centred, samples on the
    faces of the `.vol` file's box, or of that box under `toWorld`); Mitsuba 3 puts it at
    (i + 0.5)/n on [0,1]^3 under `to_world` (cell-centred). The same field is obtained in Mitsuba 3
    with a box grown by half a sample spacing h = extent/(n-1) on every side:
        to_world = toWorld_0.6 * translate(min - h/2) * scale(extent + h)
    so the cell centres land exactly on the 0.6 sample positions; inside the original box (the only
    place the medium is looked up, since the shape bounds it) the trilinear fields are identical.
"""

import os
import re
import struct
import xml.etree.ElementTree as ET

HUGE_RR_DEPTH = 1000000000

RENAMES = {  # Mitsuba 0.6 names that are not a plain camelCase -> snake_case
    "intIOR": "int_ior",
    "extIOR": "ext_ior",
    "sigmaT": "sigma_t",
    "sigmaA": "sigma_a",
    "sigmaS": "sigma_s",
    "toWorld": "to_world",
}


def snake(name):
    if name in RENAMES:
        return RENAMES[name]
    return re.sub(r"(?<=[a-z0-9])([A-Z])", lambda m: "_" + m.group(1).lower(), name)


def read_vol_header(path):
    with open(path, "rb") as f:
        head = f.read(48)
    if head[:3] != b"VOL" or head[3] != 3:
        raise ValueError(f"{path}: not a Mitsuba VOL v3 file")
    res = struct.unpack("<3i", head[8:20])
    box = struct.unpack("<6f", head[24:48])
    return res, box[:3], box[3:]


class Converter:
    def __init__(self, path, params):
        self.path = os.path.abspath(path)
        self.dir = os.path.dirname(self.path)
        self.tree = ET.parse(self.path)
        self.root = self.tree.getroot()
        if self.root.tag != "scene":
            raise ValueError(f"{path}: root element is <{self.root.tag}>, expected <scene>")
        self.values = {d.get("name"): d.get("value") for d in self.root.iter("default")}
        self.values.update(params)
        self.notes = []
        version = self.root.get("version", "3.0.0")
        self.legacy = int(version.split(".")[0]) < 2

    def subst(self, s):
        def repl(m):
            if m.group(1) not in self.values:
                raise ValueError(f"{self.path}: parameter ${m.group(1)} has no value")
            return self.values[m.group(1)]
        return re.sub(r"\$([A-Za-z_][A-Za-z0-9_]*)", repl, s)

    def note(self, s):
        if s not in self.notes:
            self.notes.append(s)

    # -- Mitsuba 0.6 -> 3 -------------------------------------------------------------------------
    def upgrade(self):
        self.root.set("version", "3.0.0")
        self.note("Mitsuba 0.6 spelling converted to Mitsuba 3 (names, spectra, grids)")
        for el in self.root.iter():
            if el.tag == "lookAt":
                el.tag = "lookat"
            if el.tag != "default" and "name" in el.attrib and el.tag not in ("ref",):
                el.set("name", snake(el.get("name")))
            if el.tag in ("spectrum", "srgb") and "value" in el.attrib:
                parts = [p for p in re.split(r"[,\s]+", self.subst(el.get("value")).strip()) if p]
                if len(parts) in (1, 3) and all(re.fullmatch(r"[-+0-9.eE]+", p) for p in parts):
                    el.tag = "rgb"
                    el.set("value", ", ".join(parts))
                else:
                    raise ValueError(f"{self.path}: cannot convert <{el.tag} value={el.get('value')!r}>")
        for medium in self.root.iter("medium"):
            if medium.get("type") == "heterogeneous":
                for child in list(medium):
                    if child.get("name") == "method":
                        medium.remove(child)
                        self.note("heterogeneous `method` dropped (Mitsuba 3 always uses majorant tracking)")
                    elif child.tag == "volume" and child.get("name") == "density":
                        child.set("name", "sigma_t")
                        self.note("heterogeneous `density` -> `sigma_t`")
            if medium.get("type") == "homogeneous":
                names = {c.get("name") for c in medium}
                if "sigma_a" in names or "sigma_s" in names:
                    raise ValueError(f"{self.path}: homogeneous sigma_a/sigma_s: write sigma_t and albedo")
        for vol in self.root.iter("volume"):
            if vol.get("type") == "gridvolume":
                self.vertex_to_cell(vol)

    def vertex_to_cell(self, vol):
        fname = self.filename_of(vol)
        res, lo, hi = read_vol_header(fname)
        old = [c for c in vol if c.tag == "transform" and c.get("name") == "to_world"]
        for c in old:
            vol.remove(c)
        t = ET.SubElement(vol, "transform", name="to_world")
        ext = [h - l for l, h in zip(lo, hi)]
        step = [e / (n - 1) if n > 1 else e for e, n in zip(ext, res)]
        # A 1-sample axis is constant in both conventions: keep the box as it is.
        grow = [s if n > 1 else 0.0 for s, n in zip(step, res)]
        ET.SubElement(t, "scale", value=", ".join(repr(e + g) for e, g in zip(ext, grow)))
        ET.SubElement(t, "translate", value=", ".join(repr(l - g / 2) for l, g in zip(lo, grow)))
        for c in old:  # the 0.6 toWorld acts on the file's box: apply it after
            for op in c:
                t.append(op)
        self.note(f"gridvolume {os.path.basename(fname)} {res[0]}x{res[1]}x{res[2]}: vertex-centred "
                  f"(0.6) -> cell-centred box grown by half a sample spacing {tuple(round(g, 6) for g in grow)}")

    # -- every scene ------------------------------------------------------------------------------
    def filename_of(self, el):
        for c in el:
            if c.tag == "string" and c.get("name") == "filename":
                f = self.subst(c.get("value"))
                return f if os.path.isabs(f) else os.path.normpath(os.path.join(self.dir, f))
        raise ValueError(f"{self.path}: <{el.tag} type={el.get('type')!r}> has no filename")

    def common(self):
        for el in self.root.iter():
            for c in el:
                if c.tag == "string" and c.get("name") == "filename":
                    f = self.filename_of(el)
                    if not os.path.exists(f):
                        raise FileNotFoundError(f"{self.path}: {f} does not exist "
                                                "(generate grids with `volpt scene generate scenes`)")
                    c.set("value", f)
        integrators = list(self.root.iter("integrator"))
        if len(integrators) != 1 or integrators[0].get("type") not in ("volpath", "volpathmis"):
            raise ValueError(f"{self.path}: needs exactly one `volpath` or `volpathmis` integrator")
        integ = integrators[0]
        rr = [c for c in integ if c.get("name") == "rr_depth"]
        if rr and int(self.subst(rr[0].get("value"))) <= 0:
            rr[0].set("value", str(HUGE_RR_DEPTH))
            self.note(f"rr_depth <= 0 (no roulette in volpt) -> {HUGE_RR_DEPTH} (Mitsuba 3 rejects <= 0)")
        if not rr:
            self.note("rr_depth not set: Russian roulette from depth 5 in both renderers")
        for s in self.root.iter("sampler"):
            if s.get("type") != "independent":
                raise ValueError(f"{self.path}: sampler {s.get('type')!r}: volpt only has `independent`")
        for f in self.root.iter("rfilter"):
            if f.get("type") != "box":
                self.note(f"rfilter {f.get('type')!r}: volpt uses box; images will differ in sharpness")

    def convert(self):
        if self.legacy:
            self.upgrade()
        self.common()
        return ET.tostring(self.root, encoding="unicode"), self.notes


def convert(path, params):
    """Returns (Mitsuba 3 XML text, notes, scene parameter names the file declares)."""
    conv = Converter(path, params)
    declared = {d.get("name") for d in conv.root.iter("default")}
    text, notes = conv.convert()
    return '<?xml version="1.0" encoding="utf-8"?>\n' + text + "\n", notes, declared


if __name__ == "__main__":
    import sys
    params = dict(a.split("=", 1) for a in sys.argv[2:])
    text, notes, _ = convert(sys.argv[1], params)
    sys.stdout.write(text)
    for n in notes:
        sys.stderr.write(f"note: {n}\n")
