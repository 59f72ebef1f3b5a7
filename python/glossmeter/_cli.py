"""The console command ``glossmeter`` that the wheel installs: the command line of the binary (the same Rust
code, ``glossmeter::cli::run_with`` with the server), so that every command, ``glossmeter serve`` included,
runs from a venv where only the wheel was installed."""
import signal
import sys

from ._glossmeter import _cli


def main() -> None:
    """Run ``glossmeter ARGS…`` and exit with its status (docs/instrument.md §Exit statuses)."""
    # Ctrl-C ends the command as it ends the binary. Python's own SIGINT handler only sets a flag that the
    # interpreter reads between bytecodes, which it never reaches while the command runs in Rust (a server
    # runs until it is stopped).
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    sys.exit(_cli(["glossmeter", *sys.argv[1:]]))


if __name__ == "__main__":
    main()
