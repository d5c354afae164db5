"""The command line ``fem-twin``: the parser and its error reporting
(:mod:`~fem_twin.cli.main`), the case commands (:mod:`~fem_twin.cli.runs`: run, traction,
compare, calibrate, fit, validate, report) and the commands that run one step of the chain
on its own (:mod:`~fem_twin.cli.steps`: topography, contact, homogenise, macro, mesh)."""

from .exits import EXIT_CODES
from .main import build_parser, main

__all__ = ["EXIT_CODES", "build_parser", "main"]
