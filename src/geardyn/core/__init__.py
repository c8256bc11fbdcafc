"""The core of geardyn: the model interface, the kernel source, run settings, the lane plan, the
section, numerical outcomes.

Nothing here imports anything of geardyn outside ``geardyn.core``; only the base modules
(:mod:`geardyn.errors`, :mod:`geardyn.units`, which import nothing of geardyn) sit below it
(``tests/test_core.py`` and ``tests/test_layers.py`` check it). The layers above (models, io,
solvers, execution, analysis, ...) build on these, never the other way round.
"""

from geardyn.core.capabilities import Capabilities
from geardyn.core.coefficients import Coefficient, CoefficientBlock, CoefficientLayout
from geardyn.core.kernel_source import KernelSource
from geardyn.core.model import Model
from geardyn.core.plan import LanePlan, LaneSettings
from geardyn.core.settings import RunSettings, SettingsError
from geardyn.core.status import Status

__all__ = ["Capabilities", "Coefficient", "CoefficientBlock", "CoefficientLayout", "KernelSource",
           "LanePlan", "LaneSettings", "Model", "RunSettings", "SettingsError", "Status"]
