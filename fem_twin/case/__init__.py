"""The case file: its sections (:mod:`~fem_twin.case.sections`, every key declared once),
the parser that validates a TOML file into a :class:`Case` (:mod:`~fem_twin.case.parse`,
each table read by :mod:`~fem_twin.case.table`).  What a run of it will cost is
:mod:`fem_twin.runtime`'s, which reads the case; the case does not know it."""

from .parse import WORKERS_PER_CORE, Case, CaseError, load_case, parse_case

__all__ = ["Case", "CaseError", "WORKERS_PER_CORE", "load_case", "parse_case"]
