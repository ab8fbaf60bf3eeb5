#!/usr/bin/env bash
# Builds the web dashboard (web/) and runs its end-to-end test in headless chromium.
# Installs nodejs/npm (only if npm is missing) and chromium from Debian; uses sudo when not root.
set -euo pipefail
cd "$(dirname "$0")/../web"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
missing=()
command -v npm >/dev/null 2>&1 || missing+=(nodejs npm)
[ -x /usr/bin/chromium ] || missing+=(chromium)
if [ ${#missing[@]} -gt 0 ]; then
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
# Vite 8 needs node >= 20.19 (the machine image ships nodejs 20 from NodeSource; Debian 12's own is 18).
node -e 'const [a, b] = process.versions.node.split(".").map(Number); process.exit(a > 20 || (a === 20 && b >= 19) ? 0 : 1)' ||
  { echo "web-test.sh: node $(node --version) is too old for Vite 8 (needs >= 20.19)" >&2; exit 1; }
npm ci --no-audit --no-fund
npm run build
npm test
