#!/usr/bin/env bash
# Installs what the browser test of the replay viewer needs: Debian's Chromium (when missing) and
# playwright-core at the version pinned in tests/browser/package-lock.json.
set -euo pipefail
cd "$(dirname "$0")"
if [ ! -x /usr/bin/chromium ]; then
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null
fi
npm ci --no-audit --no-fund --prefix .
