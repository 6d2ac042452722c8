#!/usr/bin/env bash
# Installs what the language-server client tests need: VS Code's client-side protocol library at
# the versions pinned in tests/lsp/package-lock.json (node and npm come with the machine).
set -euo pipefail
cd "$(dirname "$0")"
npm ci --no-audit --no-fund --prefix .
