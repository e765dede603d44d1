"""nprt's command line: ``python -m nprt …``, and the ``nprt`` command that
``pip install ./python`` installs (the same program as the Rust binary)."""

import signal
import sys


def main():
    """Runs the command line on ``sys.argv`` and exits with its status."""
    from ._nprt import cli

    # As the binary behaves: Ctrl-C ends the process (every command resumes), and a closed
    # pipe (`nprt ... | head`) ends it quietly.
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    if hasattr(signal, "SIGPIPE"):
        signal.signal(signal.SIGPIPE, signal.SIG_DFL)
    sys.exit(cli(["nprt", *sys.argv[1:]]))


if __name__ == "__main__":
    main()
