#!/usr/bin/env bash
# kernel/capi/install.sh PREFIX: builds the C ABI (release) and installs it
# for a C, C++ or Fortran host, as a library package would:
#   PREFIX/lib/libgranbed.a
#   PREFIX/lib/libgranbed.so.X.Y.Z, with the links libgranbed.so.<ABI> (its
#       SONAME, build.rs) and libgranbed.so (what `-lgranbed` finds)
#   PREFIX/lib/pkgconfig/granbed.pc   (pkg-config --cflags --libs granbed;
#       --variable=libdir, --variable=fortrandir)
#   PREFIX/include/granbed.h
#   PREFIX/share/granbed/fortran/granbed.f90   (module source: .mod files
#       belong to one compiler, so the host compiles it with its own)
# The processor it is built for: GRANBED_TARGET_CPU (default x86-64-v3, the
# workspace's: AVX2; x86-64 for a processor without it, the same bits), or
# RUSTFLAGS if set. Idempotent: running it again replaces the files. Extra
# arguments go to cargo build (e.g. --target-dir DIR, --target TRIPLE); the
# library installed is the one that build reports. Needs readelf.
set -euo pipefail
[[ $# -ge 1 ]] || { echo "usage: kernel/capi/install.sh PREFIX [cargo build args]" >&2; exit 2; }
prefix=$1
shift
capi=$(cd "$(dirname "$0")" && pwd)
# Where the files go must be writable before the build starts.
for dir in "$prefix/lib/pkgconfig" "$prefix/include" "$prefix/share/granbed/fortran"; do
    mkdir -p "$dir" 2>/dev/null && [[ -w $dir ]] ||
        { echo "install.sh: cannot write to $dir" >&2; exit 1; }
done
prefix=$(cd "$prefix" && pwd)
version=$(sed -n 's/^version = "\(.*\)"/\1/p' "$capi/Cargo.toml" | head -n 1)

cpu=${GRANBED_TARGET_CPU:-x86-64-v3}
export RUSTFLAGS=${RUSTFLAGS:--C target-cpu=$cpu}
# The artifacts as cargo reports them, wherever its target directory and
# target triple put them (flags, CARGO_TARGET_DIR, CARGO_BUILD_TARGET, config).
messages=$(cargo build --release --locked --manifest-path "$capi/Cargo.toml" \
    --message-format=json-render-diagnostics "$@")
artifact() {
    grep '"reason":"compiler-artifact"' <<<"$messages" | grep -o "\"[^\"]*/$1\"" | tail -n 1 | tr -d '"'
}
shared=$(artifact libgranbed.so)
static=$(artifact libgranbed.a)
[[ -f $shared && -f $static ]] || { echo "install.sh: cargo reported no libgranbed.so/.a" >&2; exit 1; }
# The ABI number is the one build.rs gave the library (its SONAME).
soname=$(readelf -d "$shared" | sed -n 's/.*Library soname: \[\(.*\)\]/\1/p')
[[ $soname == libgranbed.so.* ]] || { echo "install.sh: $shared has no SONAME" >&2; exit 1; }
abi=${soname#libgranbed.so.}

install -m 644 "$static" "$prefix/lib/libgranbed.a"
install -m 755 "$shared" "$prefix/lib/libgranbed.so.$version"
ln -sfn "libgranbed.so.$version" "$prefix/lib/$soname"
ln -sfn "$soname" "$prefix/lib/libgranbed.so"
install -m 644 "$capi/include/granbed.h" "$prefix/include/granbed.h"
install -m 644 "$capi/fortran/granbed.f90" "$prefix/share/granbed/fortran/granbed.f90"
cat >"$prefix/lib/pkgconfig/granbed.pc" <<PC
prefix=$prefix
libdir=\${prefix}/lib
includedir=\${prefix}/include
fortrandir=\${prefix}/share/granbed/fortran

Name: granbed
Description: C ABI of the granbed kernel: porous elastoplastic update, hex element forces, node-to-quad contact
Version: $version
Libs: -L\${libdir} -lgranbed
Libs.private: -lm
Cflags: -I\${includedir}
PC
echo "installed granbed $version (SONAME $soname, RUSTFLAGS $RUSTFLAGS) into $prefix"
