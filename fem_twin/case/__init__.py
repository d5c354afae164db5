"""The case file: its sections (:mod:`~fem_twin.case.sections`, every key declared once),
the parser that validates a TOML file into a :class:`Case` (:mod:`~fem_twin.case.parse`,
each table read by :mod:`~fem_twin.case.table`),
and what a run will cost before it starts (:mod:`~fem_twin.case.cost`, scaled to this
machine by :mod:`~fem_twin.case.machine`)."""

from .parse import WORKERS_PER_CORE, Case, CaseError, load_case, parse_case

__all__ = ["Case", "CaseError", "WORKERS_PER_CORE", "load_case", "parse_case"]
