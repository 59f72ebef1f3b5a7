"""Cross-check of the output schemas with an independent validator (Python `jsonschema`, Draft 2020-12).

tests/schemas.rs validates real outputs with a small structural validator written for the test; this script
runs the same kinds of outputs through the reference implementation, by hand:

    python3 tools/validate_output_schemas.py [target/debug/glossmeter]

It prints one line per output and exits 1 on the first invalid one. Needs `pip install jsonschema`.
"""
import json
import os
import subprocess
import sys
import tempfile

import jsonschema

GM = sys.argv[1] if len(sys.argv) > 1 else "target/debug/glossmeter"


def run(*args):
    p = subprocess.run([GM, *args], capture_output=True, text=True)
    if p.returncode not in (0, 1):
        sys.exit(f"{args}: exit {p.returncode}: {p.stderr}")
    return p.stdout


def schema(kind):
    s = json.loads(run("schema", "--output-format", kind))
    jsonschema.Draft202012Validator.check_schema(s)
    return jsonschema.Draft202012Validator(s)


def check(v, doc, what):
    errors = sorted(v.iter_errors(doc), key=lambda e: list(e.path))
    for e in errors:
        print(f"INVALID {what}: /{'/'.join(map(str, e.path))}: {e.message}")
    if errors:
        sys.exit(1)
    print(f"ok {what}")


tmp = tempfile.mkdtemp()
base = os.path.join(tmp, "base.json")
run("measure", "fixtures/recipes/glass-n1.5.json", "-g", "astm-d523-60", "--format", "json", "-o", base)
m = schema("measure")
for args in [
    ["measure", "fixtures/recipes/glass-n1.5.json", "--format", "json"],
    ["measure", "fixtures/recipes/phong.json", "--format", "json", "--no-timing"],
    ["measure", "fixtures/recipes/glass-n1.5.json", "fixtures/recipes/black-glass.json", "--format", "json"],
    ["measure", "fixtures/recipes/glass-n1.5.json", "-g", "astm-d523-60", "--format", "json", "--baseline", base],
]:
    check(m, json.loads(run(*args)), " ".join(args))
c = schema("compare")
for sheet in ["rhopoint-iq.csv", "byk-windows-1252.csv", "tab-separated.csv", "utf8-bom.csv"]:
    args = ["compare", "fixtures/recipes/glass-n1.5.json", f"fixtures/sheets/{sheet}", "--format", "json"]
    check(c, json.loads(run(*args)), " ".join(args))
args = ["compare", "fixtures/sheets/qc-many-samples.csv", "--recipe-dir", "fixtures/recipes", "--format", "json",
        "--baseline", base]
check(c, json.loads(run(*args)), " ".join(args))
s = schema("sweep")
args = ["sweep", "fixtures/recipes/rgb-lambert.json", "--vary", "/albedo/0=0.2..1.4:3", "-g", "astm-d523-60",
        "--format", "jsonl"]
for i, line in enumerate(run(*args).splitlines()):
    check(s, json.loads(line), " ".join(args) + f" line {i + 1}")
