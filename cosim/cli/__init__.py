"""The ``cosim`` command line: the only package that prints."""
from .app import build_parser, main

__all__ = ["build_parser", "main"]
