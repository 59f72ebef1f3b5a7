"""The console command ``glossmeter`` that the wheel installs: the command line of the binary (the same Rust
code, ``glossmeter::cli::run``), so that every command runs from a venv where only the wheel was installed.
``glossmeter serve`` needs the binary (the wheel has no server)."""
import sys

from ._glossmeter import _cli


def main() -> None:
    """Run ``glossmeter ARGS…`` and exit with its status (docs/instrument.md §Exit statuses)."""
    sys.exit(_cli(["glossmeter", *sys.argv[1:]]))


if __name__ == "__main__":
    main()
