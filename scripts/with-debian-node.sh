#!/usr/bin/env bash
# Runs a command with Debian 12's own nodejs (18) and npm (9) as /usr/bin/node
# and /usr/bin/npm, on a machine whose node is another one (a newer nodejs
# from elsewhere), without installing or replacing anything: the packages are
# fetched with `apt-get download` (nodejs, libnode108 and npm with the
# node-*/libjs-* packages they depend on that the machine lacks), unpacked with
# `dpkg -x` into a cache folder, and laid over /usr by a read-only overlay
# mount in a private mount namespace that ends with the command.
#
# Why an overlay and not PATH: Debian's libnode loads acorn, undici and
# cjs-module-lexer from fixed paths under /usr/share/nodejs, and Debian's npm
# lives there too; the build tree also records node's absolute path
# (find_program) for the browser test.
#
#   sudo bash scripts/with-debian-node.sh CMD [ARGS...]
#   e.g. sudo bash scripts/with-debian-node.sh bash -c 'node --version && npm ci && ctest ...'
#
# Needs root (unshare -m, mount) and apt sources for Debian 12 (bookworm).
# SOUPUV_DEBIAN_NODE_DIR: the cache folder (default /tmp/soupuv-debian-node).
set -euo pipefail
[ $# -gt 0 ] || { echo "usage: $0 CMD [ARGS...]" >&2; exit 2; }
dir=${SOUPUV_DEBIAN_NODE_DIR:-/tmp/soupuv-debian-node}
root="$dir/root"

if [ ! -x "$root/usr/bin/node" ] || [ ! -e "$root/usr/bin/npm" ]; then
  mkdir -p "$dir/debs"
  # Debian's nodejs 18 by version: the machine's own nodejs package may have a
  # higher version that apt would pick.
  version=$(apt-cache madison nodejs | awk '$3 ~ /^18\./ {print $3; exit}')
  [ -n "$version" ] || { echo "no nodejs 18 in the apt sources (need Debian 12)" >&2; exit 1; }
  # npm's closure, minus what the machine already has (its libraries).
  want=$(apt-cache depends --recurse --no-recommends --no-suggests --no-conflicts --no-breaks \
           --no-replaces --no-enhances npm libnode108 |
         grep -v '^ ' | grep -v '^<' | sort -u |
         grep -E '^(node-|libjs-|npm$|libnode108$|eslint$|gyp$|handlebars$|terser$|webpack$)' |
         while read -r p; do dpkg -s "$p" >/dev/null 2>&1 || echo "$p"; done)
  # _apt cannot write into a root-owned temporary folder; apt then downloads as root and says so.
  (cd "$dir/debs" && apt-get download -qq "nodejs=$version" $want 2>&1 | grep -v unsandboxed || true)
  for deb in "$dir"/debs/*.deb; do dpkg -x "$deb" "$root"; done
fi

exec unshare -m bash -c 'mount -t overlay overlay -o "lowerdir=$1/usr:/usr" /usr && shift && exec "$@"' \
  with-debian-node "$root" "$@"
