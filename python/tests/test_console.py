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


def test_the_console_command_serves_the_page_and_stops_on_ctrl_c():
    # The wheel builds the library with its server (python/Cargo.toml, features "cli" and "serve"), so a pip user
    # runs `glossmeter serve` without Rust: on port 0 (a free port, printed), it answers the API and ends on
    # Ctrl-C (SIGINT) as the binary does, killed by the signal (_cli.py restores its default action).
    import re
    import signal
    import urllib.request

    exe = _console()
    assert exe, "the wheel installs a `glossmeter` command beside the venv's python"
    usage = subprocess.run([exe, "serve", "--help"], capture_output=True, text=True)
    assert usage.returncode == 0 and "--port" in usage.stdout, usage
    proc = subprocess.Popen([exe, "serve", "--port", "0"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        line = proc.stdout.readline()
        found = re.search(r"http://127\.0\.0\.1:(\d+)/", line)
        assert found and int(found.group(1)) > 0, (line, proc.poll(), proc.stderr.read() if proc.poll() else "")
        with urllib.request.urlopen(found.group(0) + "api/fixtures", timeout=60) as reply:
            assert reply.status == 200
            doc = json.load(reply)
        names = [f["name"] for f in doc["fixtures"]]
        assert "cerulean-blue-c" in names, names
        proc.send_signal(signal.SIGINT)
        assert proc.wait(timeout=30) == -signal.SIGINT
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
