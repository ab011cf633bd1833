"""User-facing errors: the command-line front ends print these on stderr without a traceback."""


class UserError(ValueError):
    """Bad input from the user (config, paths, env ids, models): a clear message, exit code 2.

    A ValueError, as the project's convention asks for bad input.
    """


class ConfigError(UserError):
    """A configuration file or override that does not match the typed schema."""
