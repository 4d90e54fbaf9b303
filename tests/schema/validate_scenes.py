#!/usr/bin/env python3
"""navsim schema against the scene reader (issue 18, item 4).

usage: validate_scenes.py NAVSIM SCENE_DIR NEGATIVE_FILE...

1. `navsim schema` prints a valid JSON Schema (draft 2020-12) whose every leaf key has a type and a
   one-line description, and whose numeric keys carry x-unit and x-si-scale.
2. Every SCENE_DIR/*.yaml, converted to JSON with YAML 1.2 core-schema scalars (what the scene
   reader reads), validates against it; so do the scenes `navsim check` accepts.
3. Every NEGATIVE_FILE is rejected by `navsim check` (exit 2) and fails the schema: the schema is
   not looser than the reader for type, bound, unknown-key and enum mistakes.
Exit 0 when all hold, 1 with the reasons otherwise.
"""
import glob
import json
import os
import re
import subprocess
import sys

import yaml
from jsonschema import Draft202012Validator


class Yaml12Loader(yaml.SafeLoader):
    """PyYAML is YAML 1.1 (yes/no booleans, 1e3 a string, dates); the reader is YAML 1.2 core."""


Yaml12Loader.yaml_implicit_resolvers = {}
Yaml12Loader.add_implicit_resolver(
    "tag:yaml.org,2002:bool", re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$"), list("tTfF"))
Yaml12Loader.add_implicit_resolver(
    "tag:yaml.org,2002:null", re.compile(r"^(?:~|null|Null|NULL|)$"), ["~", "n", "N", ""])
Yaml12Loader.add_implicit_resolver(
    "tag:yaml.org,2002:int", re.compile(r"^(?:[-+]?[0-9]+|0o[0-7]+|0x[0-9a-fA-F]+)$"),
    list("-+0123456789"))
Yaml12Loader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"^(?:[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?"
               r"|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))$"),
    list("-+0123456789."))


def construct_int(loader, node):
    text = loader.construct_scalar(node)
    if text.startswith("0o"):
        return int(text[2:], 8)
    if text.startswith("0x"):
        return int(text[2:], 16)
    return int(text, 10)


def construct_float(loader, node):
    text = loader.construct_scalar(node).lower()
    if text.endswith(".inf"):
        return float("-inf") if text.startswith("-") else float("inf")
    if text == ".nan":
        return float("nan")
    return float(text)


Yaml12Loader.add_constructor("tag:yaml.org,2002:int", construct_int)
Yaml12Loader.add_constructor("tag:yaml.org,2002:float", construct_float)


def load_scene(path):
    with open(path, "rb") as f:
        return yaml.load(f, Loader=Yaml12Loader)


def leaves(schema, path="", out=None):
    """(path, schema) of every key of every mapping in the schema, if/then branches included."""
    if out is None:
        out = []
    if not isinstance(schema, dict):
        return out
    for key, sub in schema.get("properties", {}).items():
        p = f"{path}.{key}" if path else key
        out.append((p, sub))
        leaves(sub, p, out)
    if isinstance(schema.get("items"), dict):
        leaves(schema["items"], path + "[]", out)
    for sub in schema.get("allOf", []):
        leaves(sub.get("then", {}), path, out)
    return out


def main():
    if len(sys.argv) < 3:
        print(__doc__, file=sys.stderr)
        return 2
    navsim, scene_dir, negatives = sys.argv[1], sys.argv[2], sys.argv[3:]
    failures = []
    res = subprocess.run([navsim, "schema"], capture_output=True, text=True, check=False)
    if res.returncode != 0:
        print(f"navsim schema: exit {res.returncode}: {res.stderr}", file=sys.stderr)
        return 1
    schema = json.loads(res.stdout)
    Draft202012Validator.check_schema(schema)
    if schema.get("$schema") != "https://json-schema.org/draft/2020-12/schema":
        failures.append("$schema is not draft 2020-12")
    validator = Draft202012Validator(schema)

    # 1. the form of every key
    keys = leaves(schema)
    numeric = 0
    for path, sub in keys:
        if "type" not in sub:
            failures.append(f"{path}: no type")
            continue
        if not sub.get("description"):
            failures.append(f"{path}: no description")
        elif "\n" in sub["description"]:
            failures.append(f"{path}: description is not one line")
        types = sub["type"] if isinstance(sub["type"], list) else [sub["type"]]
        if "number" in types or ("array" in types and sub.get("items", {}).get("type") == "number"):
            numeric += 1
            if "x-unit" not in sub and path.split(".")[-1] != "limit":
                failures.append(f"{path}: numeric key without x-unit")
        if "object" in types and "properties" in sub and sub.get("additionalProperties") is not False:
            # a mapping chosen by its kind: each kind's branch rejects unknown keys
            branches = [b.get("then", {}) for b in sub.get("allOf", [])]
            if not branches or any(b.get("additionalProperties") is not False for b in branches):
                failures.append(f"{path}: mapping accepts unknown keys")
    scheme = schema["properties"]["navigation"]["properties"]["scheme"]
    if "free_ins" not in scheme.get("enum", []):
        failures.append("navigation.scheme: no enum of schemes")
    print(f"schema: {len(keys)} keys ({numeric} numeric)")

    # 2. every library scene validates
    scenes = sorted(glob.glob(os.path.join(scene_dir, "*.yaml")))
    if not scenes:
        failures.append(f"no scenes in {scene_dir}")
    for path in scenes:
        errors = sorted(validator.iter_errors(load_scene(path)), key=lambda e: list(e.absolute_path))
        for e in errors[:5]:
            where = ".".join(str(x) for x in e.absolute_path)
            failures.append(f"{path}: {where}: {e.message}")
        print(f"{'ok  ' if not errors else 'FAIL'} {os.path.basename(path)}")

    # 3. what the reader rejects, the schema rejects
    for path in negatives:
        chk = subprocess.run([navsim, "check", path], capture_output=True, text=True, check=False)
        if chk.returncode != 2:
            failures.append(f"{path}: navsim check exit {chk.returncode}, expected 2 (not a negative case)")
        reader_says = chk.stderr.strip().splitlines()[0] if chk.stderr.strip() else ""
        errors = list(validator.iter_errors(load_scene(path)))
        if not errors:
            failures.append(f"{path}: the reader rejects it ({reader_says}) but the schema accepts it")
        else:
            print(f"rejected {os.path.basename(path)}: reader: {reader_says} | schema: {errors[0].message[:100]}")

    for f in failures:
        print("FAIL: " + f, file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
