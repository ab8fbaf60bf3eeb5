#!/usr/bin/env bash
# Builds the web dashboard into web/dist/index.html (one self-contained page), which
# `mlmap export --dashboard DIR` copies. Installs nodejs/npm from Debian only if npm is
# missing; uses sudo when not root.
set -euo pipefail
cd "$(dirname "$0")/../web"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
if ! command -v npm >/dev/null 2>&1; then
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends nodejs npm
fi
# Vite 8 needs node >= 20.19 (the machine image ships nodejs 20; Debian 12's own is 18).
node -e 'const [a, b] = process.versions.node.split(".").map(Number); process.exit(a > 20 || (a === 20 && b >= 19) ? 0 : 1)' ||
  { echo "web-build.sh: node $(node --version) is too old for Vite 8 (needs >= 20.19)" >&2; exit 1; }
# A lock file newer than node_modules means a fresh install.
if [ ! -d node_modules ] || [ package-lock.json -nt node_modules ]; then
  npm ci --no-audit --no-fund --loglevel=error
fi
npm run build --silent
