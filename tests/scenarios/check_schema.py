#!/usr/bin/env python3
"""The JSON Schema and LiverSim's validator agree on every scenario file of the corpus.

Usage: check_schema.py LIVERSIM_CLI SCHEMA FILE...
A file named schema-*.json breaks a rule the schema states: both must refuse it. A file named
semantic-*.json breaks a rule between fields or against the organ, beyond what a JSON Schema says:
the schema accepts it, the validator refuses it. Any other file is valid: both accept it.
"""
import json
import pathlib
import subprocess
import sys

import jsonschema


def main():
    cli, schema_path, files = sys.argv[1], sys.argv[2], sys.argv[3:]
    schema = json.loads(pathlib.Path(schema_path).read_text(encoding="utf-8"))
    jsonschema.Draft202012Validator.check_schema(schema)
    validator = jsonschema.Draft202012Validator(schema)
    disagreements = []
    for name in files:
        path = pathlib.Path(name)
        try:
            document = json.loads(path.read_text(encoding="utf-8"))
            schema_errors = [e.message for e in validator.iter_errors(document)]
        except json.JSONDecodeError as error:
            schema_errors = [f"not JSON: {error}"]
        run = subprocess.run([cli, "validate", str(path)], capture_output=True, text=True)
        ours_accepts = run.returncode == 0
        schema_accepts = not schema_errors
        kind = path.name.split("-")[0]
        expected = {"schema": (False, False), "semantic": (True, False)}.get(kind, (True, True))
        verdict = "agree" if (schema_accepts, ours_accepts) == expected else "DISAGREE"
        print(f"{verdict}: {path.name}: schema {'accepts' if schema_accepts else 'refuses'}"
              f", validator {'accepts' if ours_accepts else 'refuses'}"
              f" (expected {'accept' if expected[0] else 'refuse'}/"
              f"{'accept' if expected[1] else 'refuse'})")
        if verdict != "agree":
            disagreements.append(path.name)
            for message in schema_errors[:3]:
                print(f"    schema: {message}")
            print("    validator: " + (run.stdout + run.stderr).strip().replace("\n", "\n    "))
    if disagreements:
        print(f"{len(disagreements)} of {len(files)} files disagree: {', '.join(disagreements)}")
        return 1
    print(f"schema and validator agree on all {len(files)} files")
    return 0


if __name__ == "__main__":
    sys.exit(main())
