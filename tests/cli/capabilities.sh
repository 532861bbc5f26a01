#!/usr/bin/env bash
# cli.capabilities — `soupuv capabilities --json` is one JSON object naming the
# commands and every map flag the help documents (the server's probe reads it).
# usage: capabilities.sh SOUPUV
set -euo pipefail
"$1" capabilities --json | /usr/bin/python3 -c '
import json, sys
j = json.load(sys.stdin)
flags, commands = set(j["map_flags"]), set(j["commands"])
missing = {"-o", "--method", "--diagnostics", "--progress", "--texture-size", "--no-uv-solve"} - flags
assert not missing, "missing map flags: %s" % sorted(missing)
assert {"map", "inspect", "capabilities"} <= commands, commands
assert all(f.startswith("-") for f in flags), flags
print(len(flags), "map flags")
'
