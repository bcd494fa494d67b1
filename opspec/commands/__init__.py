"""One module per ``opspec`` subcommand; each exposes ``register(subparsers)``."""
