"""nprt's exceptions, defined here (not in the compiled module) so that they pickle: a failure
in a ``ProcessPoolExecutor`` worker arrives with its message.

- :class:`NprtError`: any error of nprt's, with the command line's message (the file and the
  reason, each cause once).
- :class:`InputError`: an argument or a file nprt refuses (also a ``ValueError``).
- :class:`Interrupted`: Ctrl-C stopped a long call (also a ``KeyboardInterrupt``); what it
  wrote is left as the command line leaves it, resumable.
"""

__all__ = ["NprtError", "InputError", "Interrupted"]


class NprtError(RuntimeError):
    """An error of nprt's: bad input (the file and the reason) or a failed stage."""


class InputError(NprtError, ValueError):
    """An argument or input file nprt refuses, named in the message."""


class Interrupted(NprtError, KeyboardInterrupt):
    """Ctrl-C stopped the call; its outputs are left resumable, as the command line leaves them."""
