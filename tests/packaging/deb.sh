#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The test Package.Deb (tests/CMakeLists.txt): makes the Debian package of a build with `cpack -G DEB`, checks
# its control fields and contents, extracts it into a scratch root (`dpkg-deb -x`, no installation) and uses it
# there: the program's version and a solve that `check` confirms, the man page rendered by groff without a
# warning, the bash completion loaded by bash, and the user project tests/consumer built against the root's
# CMake package, which must also refuse a request for another major version.
#   deb.sh BUILD_DIR SOURCE_DIR VERSION WORK_DIR
# Exit status 0 when every check passes; otherwise 1, with the failing check's message on stderr.
set -euo pipefail
build=$1 source=$2 version=$3 work=$4

fail() {
  echo "Package.Deb: $*" >&2
  exit 1
}
# Runs a command, its output kept in $work/log; on failure the output is printed with the message.
step() {
  local what=$1
  shift
  "$@" >"$work/log" 2>&1 || {
    cat "$work/log" >&2
    fail "$what failed: $*"
  }
}
contains() { grep -qF -- "$2" <<<"$1"; }

for tool in cpack dpkg-deb dpkg-shlibdeps groff; do
  command -v "$tool" >/dev/null || fail "needs $tool (scripts/deps.sh installs dpkg-dev and groff-base)"
done
rm -rf "$work"
mkdir -p "$work"

# The package.
step "cpack" bash -c "cd '$build' && cpack -G DEB -B '$work/cpack'"
deb=$work/cpack/trivcon_${version}_$(dpkg --print-architecture).deb
[ -f "$deb" ] || fail "cpack wrote no $deb: $(ls "$work/cpack")"

# Control fields: the version of CMakeLists.txt, and Depends on the shared libraries the program links (from
# dpkg-shlibdeps), never on the GPL modules of SuiteSparse in a default build.
control=$(dpkg-deb -f "$deb")
echo "$control"
contains "$control" "Package: trivcon" || fail "the package is not named trivcon"
contains "$control" "Version: $version" || fail "the package's version is not $version"
depends=$(dpkg-deb -f "$deb" Depends)
[ -n "$depends" ] || fail "the package has no Depends"
for lib in libopenblas0 libamd2 libcamd2 zlib1g libgomp1 libstdc++6 libc6; do
  contains "$depends" "$lib" || fail "Depends lacks $lib: $depends"
done
if ! grep -q "TRIVCON_WITH_SUITESPARSE:BOOL=ON" "$build/CMakeCache.txt"; then
  for gpl in libcholmod libspqr; do
    contains "$depends" "$gpl" && fail "a default build's package depends on $gpl (GPL): $depends"
  done
fi

# Contents: the program, man page, completion, library, every public header, the CMake package, the licence.
contents=$(dpkg-deb -c "$deb" | awk '{print $NF}')
for path in ./usr/bin/trivcon ./usr/share/man/man1/trivcon.1 ./usr/share/bash-completion/completions/trivcon \
            /libtrivcon.a /cmake/trivcon/trivconConfig.cmake /cmake/trivcon/trivconConfigVersion.cmake \
            /cmake/trivcon/trivconTargets.cmake ./usr/share/doc/trivcon/LICENSE ./usr/share/doc/trivcon/THIRD_PARTY.md \
            ./usr/share/doc/trivcon/CHANGELOG.md; do
  contains "$contents" "$path" || fail "the package lacks $path"
done
for header in "$source"/include/trivcon/*.h; do
  contains "$contents" "./usr/include/trivcon/$(basename "$header")" || fail "the package lacks the header $(basename "$header")"
done

# Extracted into a scratch root, used from there.
root=$work/root
step "dpkg-deb -x" dpkg-deb -x "$deb" "$root"
trivcon=$root/usr/bin/trivcon
[ "$("$trivcon" --version)" = "trivcon $version" ] || fail "trivcon --version says '$("$trivcon" --version)', not 'trivcon $version'"
mesh=$source/data/cube_sphere.obj sings=$source/data/cube_sphere.sing
step "a solve with the packaged program" "$trivcon" solve "$mesh" -N 4 -s "$sings" --field-out "$work/field.txt" --quiet
faces=$(grep -c '^f ' "$mesh")
[ "$(grep -cv '^#' "$work/field.txt")" -eq "$faces" ] || fail "the field file has not one line per face ($faces)"
# check exits 0 only when the field's indices are exactly the prescription (4 when they differ).
step "check of the packaged program's field" "$trivcon" check "$mesh" "$work/field.txt" -N 4 -s "$sings"

# The man page: groff's warnings (-ww) on stderr; it must render without any, and say this version.
man_page=$root/usr/share/man/man1/trivcon.1
warnings=$(groff -man -Tutf8 -ww -z "$man_page" 2>&1)
[ -z "$warnings" ] || fail "groff warns about the man page: $warnings"
grep -q "^\.TH TRIVCON 1 .*trivcon $version" "$man_page" || fail "the man page's title line does not name trivcon $version"

# The completion: loads in bash and registers its function for trivcon.
completion=$root/usr/share/bash-completion/completions/trivcon
registered=$(bash -c "source '$completion' && complete -p trivcon")
contains "$registered" "-F _trivcon" || fail "the completion does not register _trivcon: $registered"

# A user's project against the root's CMake package (tests/consumer asks for trivcon 1.0: SameMajorVersion).
step "configuring tests/consumer against the package" cmake -S "$source/tests/consumer" -B "$work/consumer" \
  -DCMAKE_BUILD_TYPE=Release "-DCMAKE_PREFIX_PATH=$root/usr"
step "building tests/consumer" cmake --build "$work/consumer"
step "running tests/consumer" "$work/consumer/consumer"
cat "$work/log"

# The package's version file: this version and any lower one of the same major version are accepted, the next
# major version and the one before are not.
version_file=$(find "$root" -name trivconConfigVersion.cmake)
major=${version%%.*}
cat >"$work/version_check.cmake" <<EOF
foreach(wanted ${major}.0 ${version} $((major + 1)).0 $((major - 1)).0)
  string(REPLACE "." ";" parts "\${wanted}")
  list(LENGTH parts PACKAGE_FIND_VERSION_COUNT)
  list(GET parts 0 PACKAGE_FIND_VERSION_MAJOR)
  list(GET parts 1 PACKAGE_FIND_VERSION_MINOR)
  set(PACKAGE_FIND_VERSION_PATCH 0)
  if(PACKAGE_FIND_VERSION_COUNT GREATER 2)
    list(GET parts 2 PACKAGE_FIND_VERSION_PATCH)
  endif()
  set(PACKAGE_FIND_VERSION \${wanted})
  set(PACKAGE_VERSION_COMPATIBLE)
  set(CMAKE_SIZEOF_VOID_P 8)
  include("$version_file")
  message("\${wanted} \${PACKAGE_VERSION_COMPATIBLE}")
endforeach()
EOF
compat=$(cmake -P "$work/version_check.cmake" 2>&1)
expected="${major}.0 TRUE
${version} TRUE
$((major + 1)).0 FALSE
$((major - 1)).0 FALSE"
[ "$compat" = "$expected" ] || fail "the package's version file answers
$compat
instead of
$expected"
echo "Package.Deb: $(basename "$deb") passes (Depends: $depends)"
