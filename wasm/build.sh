#!/usr/bin/env bash
# wasm/build.sh: builds the browser calculator into wasm/www/pkg/.
#  1. rustup target add wasm32-unknown-unknown (if missing);
#  2. cargo install wasm-bindgen-cli of exactly the wasm-bindgen version in
#     Cargo.lock (if missing or another version; builds from source, about
#     10 minutes once);
#  3. cargo build --release --target wasm32-unknown-unknown -p granbed-wasm,
#     with LTO and one codegen unit (size and speed) and WebAssembly SIMD
#     (.cargo/config.toml; the floating-point operations round the same, so
#     the numbers are those of the CLI);
#  4. wasm-bindgen --target web --out-dir wasm/www/pkg.
# Idempotent. Exit status 77 (and a SKIPPED line) when no wasm32 target can
# be had (rustup missing or unable to add it); any other failure is 1.
set -euo pipefail
cd "$(dirname "$0")/.."
SKIP=77

if ! command -v rustup >/dev/null; then
    echo "wasm/build.sh: SKIPPED: no rustup, so no wasm32-unknown-unknown target"
    exit $SKIP
fi
if ! rustup target list --installed | grep -qx wasm32-unknown-unknown; then
    timeout 600 rustup target add wasm32-unknown-unknown || {
        echo "wasm/build.sh: SKIPPED: rustup could not add wasm32-unknown-unknown"
        exit $SKIP
    }
fi

# The wasm-bindgen version Cargo.lock pins; the CLI must match it exactly.
want=$(awk '/^name = "wasm-bindgen"$/ { getline; gsub(/[^0-9.]/, ""); print; exit }' Cargo.lock)
[[ -n $want ]] || { echo "wasm/build.sh: no wasm-bindgen in Cargo.lock" >&2; exit 1; }
have=$(wasm-bindgen --version 2>/dev/null | awk '{print $2}' || true)
if [[ $have != "$want" ]]; then
    echo "wasm/build.sh: cargo install wasm-bindgen-cli --version $want (have: ${have:-none})"
    cargo install wasm-bindgen-cli --version "$want"
fi

echo "wasm/build.sh: cargo build --release --target wasm32-unknown-unknown -p granbed-wasm"
# WebAssembly SIMD comes from .cargo/config.toml, which RUSTFLAGS or
# CARGO_ENCODED_RUSTFLAGS set in the environment (even empty) replace: add
# it there too (without it the module gives the same bits in about 60 %
# more time).
if [[ -v CARGO_ENCODED_RUSTFLAGS ]]; then
    export CARGO_ENCODED_RUSTFLAGS="${CARGO_ENCODED_RUSTFLAGS:+$CARGO_ENCODED_RUSTFLAGS$'\x1f'}-C"$'\x1f'"target-feature=+simd128"
elif [[ -v RUSTFLAGS ]]; then
    export RUSTFLAGS="$RUSTFLAGS -C target-feature=+simd128"
fi
CARGO_PROFILE_RELEASE_LTO=true \
    CARGO_PROFILE_RELEASE_CODEGEN_UNITS=1 \
    CARGO_PROFILE_RELEASE_DEBUG=false \
    cargo build --release --locked --target wasm32-unknown-unknown -p granbed-wasm

target_dir=${CARGO_TARGET_DIR:-$(cargo metadata --format-version 1 --no-deps |
    sed -n 's/.*"target_directory":"\([^"]*\)".*/\1/p')}
wasm=$target_dir/wasm32-unknown-unknown/release/granbed_wasm.wasm
[[ -s $wasm ]] || { echo "wasm/build.sh: $wasm missing" >&2; exit 1; }
wasm-bindgen --target web --out-dir wasm/www/pkg "$wasm"
echo "wasm/build.sh: OK wasm/www/pkg ($(stat -c %s wasm/www/pkg/granbed_wasm_bg.wasm) bytes of wasm)"
