#!/usr/bin/env bash
# wasm/browser-test/run.sh: builds the page (wasm/build.sh), computes the
# native reference runs with granbed-cli, installs playwright-core (npm ci),
# and runs the Node tests (the wasm module against the CLI) and the browser
# tests (the page in Debian's headless chromium). Exit status 77 (SKIPPED)
# when no wasm32 target or no chromium can be had; other failures are 1.
set -euo pipefail
cd "$(dirname "$0")"
HERE=$PWD
ROOT=$(cd ../.. && pwd)
SKIP=77

status=0
bash "$ROOT/wasm/build.sh" || status=$?
[[ $status == 0 ]] || exit $status

command -v node >/dev/null || { echo "browser-test: SKIPPED: no node"; exit $SKIP; }
want=$(node -p 'require("./package.json").dependencies["playwright-core"]')
have=$(node -p 'require("./node_modules/playwright-core/package.json").version' 2>/dev/null || true)
if [[ $have != "$want" ]]; then
    echo "browser-test: npm ci"
    npm ci --no-audit --no-fund --loglevel=error
fi

# The native references: the default experiment of B2 on both meshes.
native=$HERE/out/native
(cd "$ROOT" && cargo run --release --locked -q -p granbed-cli -- granule --type B2 --quiet --out "$native/B2" &&
    cargo run --release --locked -q -p granbed-cli -- granule --type B2 --mesh 4x1 --quiet --out "$native/B2-4x1")
export GRANBED_NATIVE_B2=$native/B2 GRANBED_NATIVE_B2_COARSE=$native/B2-4x1

tests=(node.test.mjs)
if [[ -x ${GRANBED_CHROMIUM:-/usr/bin/chromium} ]]; then
    tests+=(browser.test.mjs)
else
    echo "browser-test: SKIPPED the browser tests: no ${GRANBED_CHROMIUM:-/usr/bin/chromium} (.ci/setup installs Debian's chromium)"
fi
node --test --test-concurrency=1 "${tests[@]}"
[[ ${#tests[@]} == 2 ]] || exit $SKIP
