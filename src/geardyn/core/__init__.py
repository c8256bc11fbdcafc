"""The core of geardyn: run settings, the lane plan, the section, numerical outcomes.

Nothing here imports anything of geardyn outside ``geardyn.core`` (a test checks it): the
modules above (models, solvers, analysis, io, cli) build on these, never the other way round.
"""

from geardyn.core.plan import LanePlan
from geardyn.core.settings import RunSettings, SettingsError
from geardyn.core.status import Status

__all__ = ["LanePlan", "RunSettings", "SettingsError", "Status"]
