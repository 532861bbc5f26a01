#!/usr/bin/env bash
# cli.capabilities — `soupuv capabilities --json` is one JSON object naming the
# commands and every map flag (the server's probe reads "map_flags"), and the
# flag table itself ("map_options": names, value, check), from which the
# parser and the help are made too: every flag there is in the help, and the
# UV solve's flags are present.
# usage: capabilities.sh SOUPUV
set -euo pipefail
help=$("$1" --help)
"$1" capabilities --json | HELP="$help" /usr/bin/python3 -c '
import json, os, sys
j = json.load(sys.stdin)
flags, commands = set(j["map_flags"]), set(j["commands"])
missing = {"-o", "--method", "--diagnostics", "--progress", "--texture-size",
           "--uv-collapse-ratio", "--uv-untangle-iterations", "--uv-solve-iterations",
           "--uv-overlap-samples"} - flags
assert not missing, "missing map flags: %s" % sorted(missing)
# The previous UV chain and the opt-in paths no default used are gone (issue 23).
gone = {"--no-uv-solve", "--no-uv-repair", "--candidate", "--no-candidates", "--no-island-relax",
        "--repair-weld-lines", "--strict-retry", "--no-reweld"} & flags
assert not gone, "removed map flags still listed: %s" % sorted(gone)
assert {"map", "inspect", "capabilities"} <= commands, commands
assert all(f.startswith("-") for f in flags), flags
names = [n for row in j["map_options"] for n in row["names"]]
assert sorted(names) == sorted(j["map_flags"]), "map_flags is not the table"
assert len(names) == len(set(names)), "a flag has two rows"
help = os.environ["HELP"]
for row in j["map_options"]:
    assert row["names"][-1] in help, "%s not in --help" % row["names"]
    if row["value"] is not None:
        assert row["check"]["type"] in ("text", "number", "integer"), row
method = next(r for r in j["map_options"] if "--method" in r["names"])
assert set(method["check"]["words"]) == {"field", "box"}, method
print(len(flags), "map flags")
'
