#!/usr/bin/env bash
# kernel/capi/install.sh PREFIX: builds the C ABI (release) and installs it
# for a C, C++ or Fortran host, as a library package would:
#   PREFIX/lib/libgranbed.a
#   PREFIX/lib/libgranbed.so.X.Y.Z, with the links libgranbed.so.<ABI> (its
#       SONAME, build.rs) and libgranbed.so (what `-lgranbed` finds)
#   PREFIX/lib/pkgconfig/granbed.pc   (pkg-config --cflags --libs granbed)
#   PREFIX/include/granbed.h
#   PREFIX/share/granbed/fortran/granbed.f90   (module source: .mod files
#       belong to one compiler, so the host compiles it with its own)
# Idempotent: running it again replaces the files. Extra arguments go to
# cargo build (e.g. --target-dir DIR, --target TRIPLE). Needs readelf.
set -euo pipefail
[[ $# -ge 1 ]] || { echo "usage: kernel/capi/install.sh PREFIX [cargo build args]" >&2; exit 2; }
prefix=$1
shift
capi=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$prefix"
prefix=$(cd "$prefix" && pwd)

version=$(sed -n 's/^version = "\(.*\)"/\1/p' "$capi/Cargo.toml" | head -n 1)

# Where cargo puts the library: its own target directory (CARGO_TARGET_DIR
# and .cargo/config included), or --target-dir / --target given here.
target_dir=$(cargo metadata --format-version 1 --no-deps --manifest-path "$capi/Cargo.toml" |
    sed -n 's/.*"target_directory":"\([^"]*\)".*/\1/p')
triple=
args=("$@")
for ((i = 0; i < ${#args[@]}; i++)); do
    case ${args[i]} in
    --target-dir) target_dir=${args[i + 1]} ;;
    --target-dir=*) target_dir=${args[i]#--target-dir=} ;;
    --target) triple=${args[i + 1]} ;;
    --target=*) triple=${args[i]#--target=} ;;
    esac
done
[[ -n $target_dir ]] || { echo "install.sh: cannot find cargo's target directory" >&2; exit 1; }
cargo build --release --locked --manifest-path "$capi/Cargo.toml" "$@"
built=$target_dir/${triple:+$triple/}release
# The ABI number is the one build.rs gave the library (its SONAME).
soname=$(readelf -d "$built/libgranbed.so" | sed -n 's/.*Library soname: \[\(.*\)\]/\1/p')
[[ $soname == libgranbed.so.* ]] || { echo "install.sh: $built/libgranbed.so has no SONAME" >&2; exit 1; }
abi=${soname#libgranbed.so.}

install -d "$prefix/lib/pkgconfig" "$prefix/include" "$prefix/share/granbed/fortran"
install -m 644 "$built/libgranbed.a" "$prefix/lib/libgranbed.a"
install -m 755 "$built/libgranbed.so" "$prefix/lib/libgranbed.so.$version"
ln -sfn "libgranbed.so.$version" "$prefix/lib/libgranbed.so.$abi"
ln -sfn "libgranbed.so.$abi" "$prefix/lib/libgranbed.so"
install -m 644 "$capi/include/granbed.h" "$prefix/include/granbed.h"
install -m 644 "$capi/fortran/granbed.f90" "$prefix/share/granbed/fortran/granbed.f90"
cat >"$prefix/lib/pkgconfig/granbed.pc" <<PC
prefix=$prefix
libdir=\${prefix}/lib
includedir=\${prefix}/include

Name: granbed
Description: C ABI of the granbed kernel: porous elastoplastic update, hex element forces, node-to-quad contact
Version: $version
Libs: -L\${libdir} -lgranbed
Libs.private: -lm
Cflags: -I\${includedir}
PC
echo "installed granbed $version (SONAME libgranbed.so.$abi) into $prefix"
