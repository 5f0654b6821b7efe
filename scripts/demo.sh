#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Builds everything, then computes a cross field (N = 4) on the bundled mesh data/cube_sphere.obj with
# the eight +1/4 singularities of a cube (data/cube_sphere.sing), writes the field files, a report and a
# picture (field.png) to demo-output/, and prints the summary. Then the same from Python: the module installed
# into build/venv (scripts/python.sh) runs examples/cross_field.py (read, solve, edit, write, render) into
# demo-output/python/. Then it prints how to start the interactive editor on the same mesh (it does not start it),
# and last makes the quad mesh of the cube's cross field (demo-output/quads.obj, its picture quads.png).
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
echo "== the quad mesh of the cross field: its 8 irregular vertices (valence 3) are the 8 singularities"
./build/trivcon quad data/cube_sphere.obj -s data/cube_sphere.sing --target-faces 1500 -o "$out/quads.obj" --report "$out/quads.json"
./build/trivcon render "$out/quads.obj" --polygon-edges --view 35,28 --size 1000x750 -o "$out/quads.png"
echo "== wrote $out/quads.obj and its picture $out/quads.png"
