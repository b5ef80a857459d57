"""The viewer in a real browser: Debian's chromium, headless, driven by Playwright.

Usage: browser_test.py URL SCREENSHOT.png
       browser_test.py --materials URL

Opens the page, waits for a converged image and checks that it is not blank, drags the mouse
across the canvas and checks that the image changed (a new epoch, still, converged), raises the
exposure and checks that the image got brighter, and saves a screenshot of the page. With
`--materials` (a material-indexed scene of two materials, "cyan" then "white"): checks that the
panel lists both with their coefficients, then sets cyan's red absorption in its field and checks
that the server took it (the frame's parameters) and that the image changed. Exits non-zero,
saying why, on any failure. Runs against a server on loopback only.
"""

import sys
import time

from playwright.sync_api import sync_playwright

ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
        "--disable-component-update", "--disable-sync", "--no-first-run", "--disable-quic"]

# The canvas as 16x16 blocks of mean luminance (0-255), read back from the page's 2D context.
SAMPLE = """() => {
  const c = document.getElementById('view');
  const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
  const n = 16, blocks = new Array(n * n).fill(0), counts = new Array(n * n).fill(0);
  for (let y = 0; y < c.height; y++) for (let x = 0; x < c.width; x++) {
    const i = 4 * (y * c.width + x), b = Math.floor(y * n / c.height) * n + Math.floor(x * n / c.width);
    blocks[b] += 0.2126 * d[i] + 0.7152 * d[i + 1] + 0.0722 * d[i + 2]; counts[b]++;
  }
  return blocks.map((v, i) => v / counts[i]);
}"""


def stats(blocks):
    mean = sum(blocks) / len(blocks)
    std = (sum((b - mean) ** 2 for b in blocks) / len(blocks)) ** 0.5
    return mean, std


def difference(a, b):
    return sum(abs(x - y) for x, y in zip(a, b)) / len(a)


def wait_for(page, condition, what, timeout=60):
    """Waits until the JS `condition` (on `v`, the page's state) holds."""
    try:
        page.wait_for_function(f"() => {{ const v = window.volptView; return !!v && ({condition}); }}",
                               timeout=timeout * 1000)
    except Exception as e:  # noqa: BLE001 -- say what was awaited
        header = page.evaluate("() => window.volptView && window.volptView.header")
        sys.exit(f"browser test: timed out waiting for {what}; last frame header: {header} ({e})")


def converged(extra="true"):
    return (f"v.header && !v.header.interactive && v.header.spp === v.header.spp_target "
            f"&& v.header.width === v.hello.width && ({extra})")


def materials(url):
    """One edit of a material's coefficient through the panel."""
    started = time.monotonic()
    errors = []
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path="/usr/bin/chromium", args=ARGS)
        page = browser.new_page(viewport={"width": 1000, "height": 640})
        page.on("pageerror", lambda e: errors.append(str(e)))
        page.goto(url)
        wait_for(page, converged("v.header.params.materials.length === 2"), "a converged frame of two materials")
        if page.locator("#materials-box").is_hidden():
            sys.exit("browser test: the materials panel is hidden")
        legends = page.locator("#materials legend").all_inner_texts()
        if legends != ["cyan", "white"]:
            sys.exit(f"browser test: the panel lists {legends}, expected cyan and white")
        shown = page.input_value("#mat0-sigma_a0")
        if float(shown) != 6.0:
            sys.exit(f"browser test: cyan's red absorption shows {shown}, expected 6")
        before = page.evaluate(SAMPLE)
        epoch = page.evaluate("() => window.volptView.header.epoch")
        page.fill("#mat0-sigma_a0", "0.5")
        page.dispatch_event("#mat0-sigma_a0", "change")
        wait_for(page, converged(f"v.header.epoch > {epoch} && v.header.params.materials[0].sigma_a[0] === 0.5"),
                 "a converged frame with cyan's red absorption 0.5")
        after = page.evaluate(SAMPLE)
        changed = difference(before, after)
        print(f"after cyan's red absorption 6 -> 0.5: mean {stats(before)[0]:.1f} -> {stats(after)[0]:.1f}, "
              f"mean block change {changed:.1f}")
        if changed < 1.0:
            sys.exit(f"browser test: the material edit did not change the image (change {changed:.2f})")
        browser.close()
    if errors:
        sys.exit(f"browser test: the page raised {errors}")
    print(f"browser test (materials): passed in {time.monotonic() - started:.1f} s")


def main():
    if sys.argv[1] == "--materials":
        materials(sys.argv[2])
        return
    url, screenshot = sys.argv[1], sys.argv[2]
    started = time.monotonic()
    errors = []
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path="/usr/bin/chromium", args=ARGS)
        page = browser.new_page(viewport={"width": 1000, "height": 640})
        page.on("pageerror", lambda e: errors.append(str(e)))
        page.goto(url)
        wait_for(page, converged(), "a first converged frame")
        first = page.evaluate(SAMPLE)
        epoch = page.evaluate("() => window.volptView.header.epoch")
        mean, std = stats(first)
        print(f"first image: mean {mean:.1f}, block std {std:.1f} (of 255)")
        if not (2 < mean < 253 and std > 3):
            sys.exit(f"browser test: the image is blank (mean {mean:.1f}, std {std:.1f})")

        box = page.locator("#view").bounding_box()
        cx, cy = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
        page.mouse.move(cx, cy)
        page.mouse.down()
        for i in range(1, 11):
            page.mouse.move(cx + 8 * i, cy + 2 * i)
            time.sleep(0.03)
        page.mouse.up()
        wait_for(page, converged(f"v.header.epoch > {epoch}"), "a converged frame after the drag")
        dragged = page.evaluate(SAMPLE)
        moved = difference(first, dragged)
        print(f"after the drag: mean {stats(dragged)[0]:.1f}, mean block change {moved:.1f}")
        if moved < 1.0:
            sys.exit(f"browser test: the drag did not change the image (change {moved:.2f})")
        page.screenshot(path=screenshot)

        page.eval_on_selector(
            "#exposure", "e => { e.value = '1.5'; e.dispatchEvent(new Event('input')); }")
        wait_for(page, converged("v.header.exposure === 1.5"), "a frame at exposure 1.5")
        brighter = page.evaluate(SAMPLE)
        gain = stats(brighter)[0] - stats(dragged)[0]
        print(f"after exposure +1.5: mean {stats(brighter)[0]:.1f} ({gain:+.1f})")
        if gain < 5:
            sys.exit(f"browser test: the exposure did not brighten the image ({gain:+.1f})")
        browser.close()
    if errors:
        sys.exit(f"browser test: the page raised {errors}")
    print(f"browser test: passed in {time.monotonic() - started:.1f} s; screenshot {screenshot}")


if __name__ == "__main__":
    main()
