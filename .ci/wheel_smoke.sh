#!/usr/bin/env bash
# The wheel we ship, installed where there is no Rust (issue 20).
#
# 1. Builds the release wheel as we ship it: one abi3 wheel (CPython >= 3.10) tagged
#    manylinux2014 (glibc >= 2.17), linked with zig (maturin --zig) so that the glibc symbols
#    it needs are those of manylinux2014 whatever the build machine's glibc; auditwheel must
#    agree with the tag.
# 2. Installs it (binary packages only) into a fresh venv in a temporary directory and, with
#    no cargo or rustc on PATH, runs a simulation, a small sweep, `granrs run` and
#    `granrs animate` on an example scene.
# 3. Builds the sdist (maturin sdist) and a wheel from it, and checks its contents.
#
# Installs what it needs itself (maturin, ziglang, auditwheel from PyPI, into a venv of its
# own). Prints "wheel-smoke: ..." lines; exits non-zero on the first failure.
set -euo pipefail
cd "$(dirname "$0")/.."
repo=$(pwd)
started=$(date +%s)
export PIP_DISABLE_PIP_VERSION_CHECK=1
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$repo/target}"

say() { echo "wheel-smoke: $*"; }
fail() {
    echo "wheel-smoke: FAILED: $*" >&2
    exit 1
}

work=$(mktemp -d "${TMPDIR:-/tmp}/granrs-wheel-smoke.XXXXXX")
trap 'rm -rf "$work"' EXIT

arch=$(uname -m)
expected_tag="manylinux_2_17_${arch}"
expected_suffix="cp310-abi3-manylinux2014_${arch}.manylinux_2_17_${arch}.whl"

# --- build tools, in their own venv ------------------------------------------------------------
say "installing the build tools (maturin, ziglang, auditwheel) into $work/tools"
python3 -m venv "$work/tools"
"$work/tools/bin/pip" install -q "maturin>=1.9.4,<2" "ziglang>=0.11" "auditwheel>=6"
tools_path="$work/tools/bin:$PATH"

# --- 1. the wheel ------------------------------------------------------------------------------
# In a target directory of its own: this build shares nothing with the others (zig links it,
# for an explicit --target), and so it never waits for their lock, nor they for its.
say "building the wheel: maturin build --release --zig --compatibility manylinux2014"
PATH="$tools_path" maturin build --release --zig --compatibility manylinux2014 \
    --target-dir "$CARGO_TARGET_DIR/wheel-smoke-zig" --out "$work/dist" --quiet ||
    fail "maturin build"
wheels=("$work"/dist/*.whl)
[ "${#wheels[@]}" -eq 1 ] || fail "expected one wheel, got: ${wheels[*]}"
wheel=${wheels[0]}
say "built $(basename "$wheel")"
case "$(basename "$wheel")" in
*"$expected_suffix") ;;
*) fail "the wheel's tag is not abi3 manylinux2014: $(basename "$wheel")" ;;
esac
audit=$(PATH="$tools_path" auditwheel show "$wheel" | tr -s ' \n' ' ' | sed "s/^ //")
say "auditwheel: ${audit%%. The wheel references*}"
case "$audit" in
*"consistent with the following platform tag: \"$expected_tag\""*) ;;
*) fail "auditwheel does not find the wheel consistent with $expected_tag: $audit" ;;
esac

# --- 2. install and run it with no Rust on PATH ------------------------------------------------
say "installing the wheel into a fresh venv ($work/venv)"
python3 -m venv "$work/venv"
clean_path="$work/venv/bin:/usr/bin:/bin"
in_venv() { (cd "$work" && env -u PYTHONPATH -u VIRTUAL_ENV -u CARGO_TARGET_DIR PATH="$clean_path" "$@"); }
if in_venv sh -c 'command -v cargo || command -v rustc'; then
    fail "cargo or rustc is on the smoke test's PATH ($clean_path)"
fi
say "no cargo or rustc on PATH=$clean_path"
in_venv pip install -q --only-binary=:all: "$wheel" || fail "pip install of the wheel"

say "python: simulate, sweep"
in_venv python - <<'EOF' || fail "the Python smoke test"
import math
import sys

import granrs

where = granrs._granrs.__file__
print(f"wheel-smoke: granrs {granrs.__version__}, core {where}")
assert "site-packages" in where and where.endswith(".abi3.so"), where

result = granrs.simulate(granrs.cases.free_link(q_deg=45, v0=2.27))
print(
    f"wheel-smoke: free link q = 45 deg, v0 = 2.27 m/s: {result.status}, "
    f"t_s = {result.t_s * 1e3:.2f} ms, depth = {result.depth * 1e3:.2f} mm"
)
# The thesis's experiment (Table 3.1 row 4) stopped at about 30 mm; any working core is near.
assert result.status == "stopped" and 0.01 < result.depth < 0.05, result

base = granrs.cases.free_link(q_deg=0, v0=2.27)
df = granrs.sweep(base, q_deg=[30.0, 45.0], v0=[1.0, 2.27], threads=2, progress=False)
print(df[["q_deg", "v0", "status", "t_s", "depth"]].to_string(index=False))
assert len(df) == 4 and (df["status"] == "stopped").all(), df
# A sweep's row is the scene run alone: the q = 45, v0 = 2.27 row is the run above
# (the same coefficients: the free_link case picks Table 3.4 by angle, sweep keeps base's).
alone = granrs.simulate(base.replace(q_deg=45.0))
row = df[(df["q_deg"] == 45.0) & (df["v0"] == 2.27)].iloc[0]
assert row["depth"] == alone.depth and (row["t_s"] == alone.t_s or math.isnan(alone.t_s))
print("wheel-smoke: python checks passed")
sys.exit(0)
EOF

say "granrs run examples/scenes/free_link_q45.toml"
out=$(in_venv granrs run "$repo/examples/scenes/free_link_q45.toml") || fail "granrs run"
echo "$out" | sed 's/^/    /'
echo "$out" | grep -q "status stopped" || fail "granrs run did not report 'status stopped'"

say "granrs animate examples/scenes/free_link_q45.toml --out impact.gif"
in_venv granrs animate "$repo/examples/scenes/free_link_q45.toml" --out "$work/impact.gif" \
    --frame-dt 0.01 --dpi 50 || fail "granrs animate"
[ "$(head -c 6 "$work/impact.gif")" = "GIF89a" ] || fail "granrs animate wrote no GIF"

# --- 3. the sdist builds -----------------------------------------------------------------------
say "building the sdist (maturin sdist) and a wheel from it"
PATH="$tools_path" maturin sdist --out "$work/sdist" >/dev/null || fail "maturin sdist"
sdists=("$work"/sdist/granrs-*.tar.gz)
(cd "$work" && PATH="$tools_path" pip wheel -q --no-deps -w "$work/from-sdist" "${sdists[0]}") ||
    fail "pip wheel of the sdist"
listing=$("$work/venv/bin/python" -m zipfile -l "$work"/from-sdist/granrs-*.whl)
for needed in granrs/_granrs granrs/data/table_3_4_free_link_coefficients.csv granrs/animation.py granrs/_constructors.pyi granrs/py.typed; do
    echo "$listing" | grep -q "$needed" || fail "the wheel built from the sdist lacks $needed"
done
say "the sdist $(basename "${sdists[0]}") builds a wheel with the core and the data"

say "passed in $(($(date +%s) - started)) s"
