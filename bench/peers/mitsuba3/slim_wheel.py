#!/usr/bin/env python3
"""Slim the mitsuba wheel to the variants the peer comparison needs, so that it fits the device
machine's carry limit (64 MiB for everything carried).

  python3 bench/peers/mitsuba3/slim_wheel.py bundle-peer/dl/mitsuba-3.9.1-cp312-*.whl -o bundle-peer

Drops every `mitsuba/<variant>.cpython-*.so` whose variant is not kept, `mitsuba/include/` (C++
headers, only for building plugins), and with --drop-spectral-data `mitsuba/data/srgb.coeff` (the
RGB-to-spectrum table, which only spectral variants read; 8.9 MB compressed); rewrites
`MI_VARIANTS` in `mitsuba/config.py` and regenerates the wheel's RECORD (sha256 and size of every
file). The wheel keeps its name, so pip installs it as mitsuba 3.9.1.
"""

import argparse
import ast
import base64
import hashlib
import os
import re
import sys
import zipfile

DEFAULT_VARIANTS = ["scalar_rgb", "llvm_ad_rgb", "cuda_ad_rgb"]


def record_hash(data):
    digest = hashlib.sha256(data).digest()
    return "sha256=" + base64.urlsafe_b64encode(digest).rstrip(b"=").decode()


def slim(src, dst, keep, drop_spectral_data):
    variant_so = re.compile(r"^mitsuba/([a-z0-9_]+)\.cpython-[^/]*\.so$")
    zin = zipfile.ZipFile(src)
    names = zin.namelist()
    config = zin.read("mitsuba/config.py").decode()
    listed = re.search(r"^MI_VARIANTS = (\[.*\])$", config, flags=re.M)
    if not listed:
        raise SystemExit(f"{src}: mitsuba/config.py has no MI_VARIANTS line")
    variants = set(ast.literal_eval(listed.group(1)))
    known = {m.group(1) for n in names if (m := variant_so.match(n)) and m.group(1) in variants}
    missing = set(keep) - known
    if missing:
        raise SystemExit(f"{src}: no module for variant(s) {sorted(missing)}; it has {sorted(known)}")
    record_name = next(n for n in names if n.endswith(".dist-info/RECORD"))
    dropped, kept_bytes, records = [], 0, []
    with zipfile.ZipFile(dst, "w", compression=zipfile.ZIP_DEFLATED, compresslevel=9) as zout:
        for info in zin.infolist():
            n = info.filename
            m = variant_so.match(n)
            if (m and m.group(1) in variants and m.group(1) not in keep) or n.startswith("mitsuba/include/") or \
                    (drop_spectral_data and n == "mitsuba/data/srgb.coeff"):
                dropped.append(n)
                continue
            if n == record_name:
                continue
            data = zin.read(n)
            if n == "mitsuba/config.py":
                text = data.decode()
                text, count = re.subn(r"^MI_VARIANTS = \[.*\]$", f"MI_VARIANTS = {keep!r}", text, flags=re.M)
                if count != 1:
                    raise SystemExit("mitsuba/config.py: no MI_VARIANTS line to rewrite")
                data = text.encode()
            out = zipfile.ZipInfo(n, date_time=info.date_time)
            out.external_attr = info.external_attr
            out.compress_type = zipfile.ZIP_DEFLATED
            zout.writestr(out, data)
            records.append(f"{n},{record_hash(data)},{len(data)}")
            kept_bytes += len(data)
        records.append(f"{record_name},,")
        rec = zipfile.ZipInfo(record_name, date_time=zin.getinfo(record_name).date_time)
        rec.external_attr = zin.getinfo(record_name).external_attr
        zout.writestr(rec, ("\n".join(records) + "\n").encode(), compress_type=zipfile.ZIP_DEFLATED)
    return dropped, kept_bytes


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("wheel")
    ap.add_argument("-o", "--out-dir", required=True)
    ap.add_argument("--variants", nargs="+", default=DEFAULT_VARIANTS)
    ap.add_argument("--drop-spectral-data", action="store_true",
                    help="also drop mitsuba/data/srgb.coeff (only spectral variants read it)")
    args = ap.parse_args()
    os.makedirs(args.out_dir, exist_ok=True)
    dst = os.path.join(args.out_dir, os.path.basename(args.wheel))
    if os.path.abspath(dst) == os.path.abspath(args.wheel):
        raise SystemExit("the output would overwrite the input")
    dropped, kept = slim(args.wheel, dst, args.variants, args.drop_spectral_data)
    print(f"{dst}: {os.path.getsize(dst) / 1e6:.1f} MB (was {os.path.getsize(args.wheel) / 1e6:.1f} MB), "
          f"{kept / 1e6:.1f} MB unpacked; dropped {len(dropped)} files; variants {args.variants}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
