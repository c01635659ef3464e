"""Exceptions raised by gcmh_core for bad input and for cancelled runs."""


class InputError(ValueError):
    """Bad input from a user: the message says what is wrong and where."""


class Cancelled(RuntimeError):
    """Raised inside `extract` when the `cancel` callback returns True."""


class TooLargeError(InputError):
    """A run that would need more memory or time than this machine gives: the message
    names the estimate (`gcmh_core.budget`) and what to change; `force=True` runs it anyway."""
