#!/usr/bin/env bash
# The viewer in a real browser (CI): installs Debian's chromium and Playwright for Python (in a
# venv; Playwright's own browser download is never used), starts `volpt view` on 127.0.0.1 with
# the CPU backend and a small scene, and runs volpt-view/browser_test.py against it. The screenshot
# goes to target/viewer.png; `bash volpt-view/browser-test.sh docs/viewer.png` renews the one in the
# docs (CI leaves tracked files alone).
set -euo pipefail
cd "$(dirname "$0")/.."
screenshot=${1:-target/viewer.png}
started=$SECONDS

if [[ ! -x /usr/bin/chromium ]]; then
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null
fi
venv=target/browser-test-venv
if ! "$venv/bin/python" -c 'import playwright' 2>/dev/null; then
    python3 -m venv "$venv"
    "$venv/bin/pip" install -q playwright
fi
# The binary as the README's `cargo test --release` builds it (CI's step before this one, so a
# no-op there): a plain `cargo build -p volpt-cli` unifies other dependency features and would
# rebuild the workspace.
cargo test --release --no-run -q

log=$(mktemp)
trap 'rm -f "$log"' EXIT
# serve WHAT SCENE VIEW-FLAGS...: starts `volpt view` on a free port; sets `server` and `url`.
serve() {
    local what=$1 scene=$2
    shift 2
    target/release/volpt view "$scene" "$@" --threads 2 --bind 127.0.0.1:0 >"$log" 2>&1 &
    server=$!
    trap 'kill "$server" 2>/dev/null || true; rm -f "$log"' EXIT
    url=
    for _ in $(seq 100); do
        url=$(sed -n 's/^volpt view: open //p' "$log")
        [[ -n $url ]] && break
        kill -0 "$server" 2>/dev/null || { cat "$log"; echo "browser test: volpt view exited ($what)"; exit 1; }
        sleep 0.1
    done
    [[ -n $url ]] || { cat "$log"; echo "browser test: no URL from volpt view ($what)"; exit 1; }
}
# Ctrl-C ends the server cleanly: SIGINT, then it must exit 0 by itself.
stop() {
    kill -INT "$server"
    wait "$server"
    trap 'rm -f "$log"' EXIT
}

serve cube scenes/example/cube.xml --resolution 240x240 --spp 16
"$venv/bin/python" volpt-view/browser_test.py "$url" "$screenshot"
stop

# A material-indexed print (two resins in an 8 x 8 x 4 u8 index grid): the panel lists its
# materials, and one edit of a material's absorption changes the image.
print=target/browser-test-print
mkdir -p "$print"
python3 - "$print" <<'EOF'
import sys
out = sys.argv[1]
index = bytes((x // 4 + y // 4 + z) % 2 for z in range(4) for y in range(8) for x in range(8))
open(f"{out}/print.raw", "wb").write(index)
open(f"{out}/print.toml", "w").write('''[volume]
file = "print.raw"
format = "raw"
type = "u8"
resolution = [8, 8, 4]
bounds = [[-1.0, -1.0, -0.5], [1.0, 1.0, 0.5]]
[boundary]
bsdf = "null"
[camera]
origin = [0.0, -3.0, 4.0]
target = [0.0, 0.0, 0.0]
fov = 40.0
[[materials]]
name = "cyan"
sigma_s = [4.0, 6.0, 7.0]
sigma_a = [6.0, 0.8, 0.2]
[[materials]]
name = "white"
sigma_s = 6.0
sigma_a = 0.05
''')
EOF
serve print "$print/print.toml" --resolution 160x160 --spp 8
"$venv/bin/python" volpt-view/browser_test.py --materials "$url"
stop
echo "browser test: $((SECONDS - started)) s in all (installs and build included)"
