#!/usr/bin/env bash
# Builds the web dashboard (web/) and runs its end-to-end test in headless chromium.
# Installs chromium from Debian when missing (sudo when not root); scripts/web-build.sh
# does the rest of the set-up.
set -euo pipefail
cd "$(dirname "$0")/.."
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
if [ ! -x /usr/bin/chromium ]; then
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends chromium
fi
bash scripts/web-build.sh
cd web
npm test
