"""Command-line sub-commands; each module defines ``register(subparsers)``."""
