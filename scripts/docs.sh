#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Builds the documentation site into build/docs/ (open build/docs/index.html) from the Markdown pages of docs/:
# installs Sphinx, furo, breathe, doxygen and myst-parser from Debian (scripts/deps.sh --docs), brings the program
# and the Python module up to date (scripts/build.sh, and scripts/python.sh when the installed module is missing
# or older than its sources: autodoc imports it from build/venv), generates the command-line reference from the
# program's own help (scripts/cli_help.py, into docs/reference/generated/), runs doxygen on the headers (docs/Doxyfile, into
# build/doxygen/) and Sphinx. Warnings of doxygen and of Sphinx are errors. Used by scripts/test.sh.
# Why these tools: docs/development/testing.md, "The documentation site".
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/deps.sh --docs
start=$(date +%s)
bash scripts/build.sh  # incremental: nothing to do when the build is current
# The module autodoc documents: installed again when missing or older than its sources.
installed=$(build/venv/bin/python -c 'import trivcon, os; print(os.path.dirname(trivcon.__file__))' 2>/dev/null || true)
if [ -z "$installed" ] || [ -n "$(find python/trivcon python/src -newer "$installed/__init__.py" -print -quit)" ]; then
  bash scripts/python.sh
fi
python3 scripts/cli_help.py --program build/trivcon --format markdown --out docs/reference/generated
rm -rf build/doxygen
mkdir -p build/doxygen
TRIVCON_DOXYGEN_OUT=build/doxygen doxygen docs/Doxyfile
TRIVCON_DOXYGEN_XML=$PWD/build/doxygen/xml build/venv/bin/python -m sphinx -W --keep-going -q -b html \
  -d build/docs-doctrees docs build/docs
echo "== docs: the site is in build/docs/ (index.html), built in $(($(date +%s) - start)) s"
