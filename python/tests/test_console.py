"""The wheel's console command ``glossmeter`` (``glossmeter/_cli.py``): installed beside the venv's Python, it
runs the command line's own code, so its documents are the binary's byte for byte."""
import json
import os
import pathlib
import shutil
import subprocess
import sys

from conftest import RECIPES


def _console():
    here = pathlib.Path(sys.executable).parent
    for name in ("glossmeter", "glossmeter.exe"):
        if (here / name).is_file():
            return str(here / name)
    return shutil.which("glossmeter")


def test_the_console_command_runs_the_command_line():
    exe = _console()
    assert exe, "the wheel installs a `glossmeter` command beside the venv's python"
    out = subprocess.run([exe, "--version"], capture_output=True, text=True)
    assert out.returncode == 0 and out.stdout.startswith("glossmeter "), out
    recipe = str(RECIPES / "glass-n1.5.json")
    args = ["measure", recipe, "-g", "astm-d523-60", "--format", "json", "--no-timing"]
    out = subprocess.run([exe, *args], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    doc = json.loads(out.stdout)
    assert doc["readings"][0]["geometry"] == "astm-d523-60" and doc["readings"][0]["value"] > 50
    # Bad input: exit 2 and the flag named, as the binary does.
    bad = subprocess.run([exe, "measure", recipe, "--rtol", "2"], capture_output=True, text=True)
    assert bad.returncode == 2 and "--rtol" in bad.stderr, bad
    binary = os.environ.get("GLOSSMETER_BIN")
    if binary and pathlib.Path(binary).is_file():
        same = subprocess.run([binary, *args], capture_output=True, text=True)
        assert same.stdout == out.stdout


def test_the_console_module_runs_without_the_script():
    out = subprocess.run([sys.executable, "-m", "glossmeter._cli", "standards"], capture_output=True, text=True)
    assert out.returncode == 0 and "astm-d523-60" in out.stdout, out
