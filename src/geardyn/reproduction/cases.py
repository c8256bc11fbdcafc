"""The paper's figure cases (Figs. 3-15, 15a-d), each a built-in study ``geardyn/studies``.

A case is a figure of the seed paper: a study file with the parameters the paper states for it and
the coordinate it plots. Several figures share their dynamics and differ only in the coordinate
shown (Figs. 3/6, 4/7, 5/8, 9/10, 11/12): :meth:`Case.dynamics_key` is equal for those, so a
reproduction runs each distinct parameter set once.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from functools import cached_property

from geardyn.errors import StudyError
from geardyn.io.toml import Study, builtin_study
from geardyn.models.params import PlanetaryParams

__all__ = ["CASE_NAMES", "Case", "get_case", "paper_cases"]

#: Every figure case of the paper, in the paper's order.
CASE_NAMES: tuple[str, ...] = (
    "fig3", "fig4", "fig5", "fig6", "fig7", "fig8", "fig9", "fig10", "fig11", "fig12",
    "fig13", "fig14", "fig15a", "fig15b", "fig15c", "fig15d",
)


@dataclass(frozen=True)
class Case:
    """One figure of the paper: ``name`` ("fig3") and its built-in study ("paper_fig3")."""

    name: str

    @property
    def study_name(self) -> str:
        return f"paper_{self.name}"

    @property
    def figure(self) -> str:
        """The paper's label: "Fig. 3", "Fig. 15a"."""
        return f"Fig. {self.name[3:]}"

    @cached_property
    def study(self) -> Study:
        return builtin_study(self.study_name)

    @property
    def params(self) -> PlanetaryParams:
        return self.study.planetary_params

    @property
    def plot_state(self) -> str:
        return self.study.plot_state

    @property
    def load_noise(self) -> bool:
        """True when a load torque fluctuates (B1 or B2 != 0 at Lambda > 0, Eq. 14): a second
        forcing frequency, so the once-per-mesh-period section no longer shows the motion's
        period unless Lambda / Omega is rational with a small denominator."""
        loads = self.params.loads
        return loads.Lambda > 0.0 and (loads.B1 != 0.0 or loads.B2 != 0.0)

    def dynamics_key(self, interpretation: str) -> str:
        """Equal for cases with the same motion (parameters, run and sweep settings); the
        plotted coordinate is not part of it."""
        s = self.study
        doc = {
            "params": self.params.model_dump(mode="json"),
            "run": s.run.model_dump(mode="json"),
            "sweep": s.sweep.model_dump(mode="json", exclude={"continuation"})
            if s.sweep else None,
            "interpretation": interpretation,
        }
        text = json.dumps(doc, sort_keys=True)
        return hashlib.sha256(text.encode()).hexdigest()[:16]


def paper_cases() -> list[Case]:
    """All figure cases, in the paper's order."""
    return [Case(n) for n in CASE_NAMES]


def get_case(name: str) -> Case:
    """A case by name: ``fig3``, ``3``, ``Fig. 3``, ``paper_fig3`` or ``15a``."""
    key = name.strip().lower().replace(" ", "").replace(".", "")
    key = key.removeprefix("paper_").removeprefix("fig")
    if f"fig{key}" in CASE_NAMES:
        return Case(f"fig{key}")
    raise StudyError(f"case: unknown figure case {name!r}; known: {', '.join(CASE_NAMES)}")
