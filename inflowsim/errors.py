"""Exceptions that mean "the user's input is wrong" (exit status 2 on the command line)."""


class InputError(ValueError):
    """Bad user input: a parameter, option or file.  The message is one line."""


class RecordError(InputError):
    """A flight-test record that does not follow ``record-format.md``."""


__all__ = ["InputError", "RecordError"]
