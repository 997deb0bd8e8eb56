"""User-facing errors: each carries one line that says what is wrong and where."""


class RailMonitorError(Exception):
    """An error the user can act on; front ends print its message alone, without a traceback."""


class ConfigError(RailMonitorError):
    """A site or node parameter is missing, of the wrong type or out of its allowed range."""


class InputError(RailMonitorError):
    """A history file (bag or CSV) cannot be read or does not hold usable train passes."""


class PassOrderError(InputError):
    """Passes given in chunks are not in time order (a chunk older than an earlier one)."""
