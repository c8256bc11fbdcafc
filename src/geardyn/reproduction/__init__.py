"""The seed paper's study reproduced: its figure cases, its claims checked against the data,
and a report (``geardyn reproduce``; see ``docs/reproduction.md``)."""

from geardyn.reproduction.cases import CASE_NAMES, Case, get_case, paper_cases
from geardyn.reproduction.claims import CLAIMS, Claim, Verdict, evaluate
from geardyn.reproduction.report import write_report
from geardyn.reproduction.runner import ReproductionSettings, run_case, run_cases

__all__ = [
    "CASE_NAMES",
    "CLAIMS",
    "Case",
    "Claim",
    "ReproductionSettings",
    "Verdict",
    "evaluate",
    "get_case",
    "paper_cases",
    "run_case",
    "run_cases",
    "write_report",
]
