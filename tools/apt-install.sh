#!/usr/bin/env bash
# Installs those of the Debian packages named that are missing: as root, after apt-get
# update; as another user, it names the missing ones and fails. tools/setup.sh and
# tools/install-python.sh call it with their lists.
set -euo pipefail
missing=()
for p in "$@"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "$(id -u)" = 0 ]; then
  apt-get update -q
  [ ${#missing[@]} -eq 0 ] || DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}"
elif [ ${#missing[@]} -ne 0 ]; then
  echo "portalsim: missing packages (run as root to install): ${missing[*]}" >&2
  exit 1
fi
