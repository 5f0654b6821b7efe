#!/usr/bin/env bash
# Builds everything, then computes a cross field (N = 4) on the bundled mesh data/cube_sphere.obj with
# the eight +1/4 singularities of a cube (data/cube_sphere.sing), writes the field files, a report and a
# picture (field.png) to demo-output/, and prints the summary. Then the same from Python: the module installed
# into build/venv (scripts/python.sh) runs examples/cross_field.py (read, solve, edit, write, render) into
# demo-output/python/. Last, it prints how to start the interactive editor on the same mesh (it does not start it).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
out=demo-output
mkdir -p "$out"
./build/trivcon info data/cube_sphere.obj
./build/trivcon solve data/cube_sphere.obj -N 4 -s data/cube_sphere.sing \
  --field-out "$out/field.txt" --connection-out "$out/connection.txt" --lines-out "$out/field_lines.obj" \
  --report "$out/report.json" --png "$out/field.png"
./build/trivcon check data/cube_sphere.obj "$out/field.txt" -N 4 -s data/cube_sphere.sing
echo "== wrote $(ls "$out" | tr '\n' ' ')to $out/"
bash scripts/python.sh
./build/venv/bin/python examples/cross_field.py --out "$out/python"
echo "== the interactive editor (prints a URL to open in a browser; Ctrl+C stops it):"
echo "   ./build/trivcon edit data/cube_sphere.obj -N 4 -s data/cube_sphere.sing"
