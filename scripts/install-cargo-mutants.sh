#!/usr/bin/env bash
# Installs the cargo-mutants version the mutation scripts were written against, if another (or
# none) is installed: one pin for scripts/mutants.sh and scripts/gpu-mutants.sh.
set -euo pipefail
version=27.1.0
if ! cargo mutants --version 2>/dev/null | grep -qF "$version"; then
    cargo install cargo-mutants --locked --version "$version"
fi
