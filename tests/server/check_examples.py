#!/usr/bin/env python3
"""proto/examples/*.json against the contract: job-*.json against
proto/job.schema.json, problem-*.json against openapi.yaml's Problem schema.
usage: check_examples.py SOURCE_DIR   (prints 'N passed, M failed')"""
import glob
import json
import os
import sys

import yaml

src = sys.argv[1]
job_schema = json.load(open(os.path.join(src, "proto/job.schema.json")))
problem_schema = yaml.safe_load(open(os.path.join(src, "proto/openapi.yaml")))["components"]["schemas"]["Problem"]
try:
    import jsonschema

    def validate(doc, schema):
        jsonschema.Draft202012Validator(schema).validate(doc)
except ImportError:  # without the validator: required keys and the state enum
    def validate(doc, schema):
        missing = [k for k in schema.get("required", []) if k not in doc]
        if missing:
            raise ValueError(f"missing {missing}")
        enum = schema.get("properties", {}).get("state", {}).get("enum")
        if enum and doc["state"] not in enum:
            raise ValueError("bad state")

passed = failed = 0
for path in sorted(glob.glob(os.path.join(src, "proto/examples/*.json"))):
    name = os.path.basename(path)
    schema = job_schema if name.startswith("job-") else problem_schema if name.startswith("problem-") else None
    if schema is None:
        continue
    try:
        validate(json.load(open(path)), schema)
        passed += 1
        print("ok  ", name)
    except Exception as e:  # noqa: BLE001 - report any validation failure
        failed += 1
        print("FAIL", name, e)
print(f"{passed} passed, {failed} failed")
sys.exit(1 if failed or not passed else 0)
