"""Exceptions raised by gcmh_core for bad input and for cancelled runs."""


class InputError(ValueError):
    """Bad input from a user: the message says what is wrong and where."""


class Cancelled(RuntimeError):
    """Raised inside `extract` when the `cancel` callback returns True."""
