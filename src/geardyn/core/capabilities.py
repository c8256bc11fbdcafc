"""What a model offers beyond the model interface, declared by the model's class.

Analyses, io and the CLI read :attr:`geardyn.core.model.Model.capabilities` instead of probing
attributes (``hasattr(model, "omega_n")``) or classes (``isinstance(model, CATTDevice)``).
"""

from __future__ import annotations

from dataclasses import dataclass

#: The sensor signals a model may declare for a fault dataset, each with the sensor settings it
#: takes (``FaultDatasetSpec.sensor``): ``"mesh_force"``, the force observable of one of the
#: model's meshes (``mesh``: its name; default the first mesh); ``"ring_sensor"``, a planetary
#: stage's ring sensor (:func:`geardyn.analysis.sensor.sensor_signal`, the ring-planet forces
#: through the planet-pass window).
DATASET_SIGNALS: dict[str, tuple[str, ...]] = {
    "mesh_force": ("mesh",),
    "ring_sensor": ("sensor_angle", "width", "window"),
}


@dataclass(frozen=True)
class FaultDatasetInputs:
    """What a model class offers a labelled fault dataset (:func:`geardyn.fault_dataset`).

    ``speed``, ``torque``
        The ``with_params`` names of its speed input and its torque input.
    ``speed_unit``
        The unit a number of the speed input is in (``"rpm"``), or None: the instance's own
        ``speed_unit`` (a model that reads plain numbers in a unit it was built with).
    ``torque_unit``
        The unit of the torque input (``"N m"``).
    ``signal``
        Its sensor signal, a key of :data:`DATASET_SIGNALS` (``"mesh_force"`` needs the
        ``mesh_forces`` capability).
    ``signal_units``
        The signal's unit.
    ``stiffness_error``
        ``model.stiffness_error()`` gives the truncation errors of its stiffness series (name
        -> relative error), recorded per fault.
    """

    speed: str
    torque: str
    signal: str
    speed_unit: str | None = "rpm"
    torque_unit: str = "N m"
    signal_units: str = "N"
    stiffness_error: bool = False

    def __post_init__(self) -> None:
        if self.signal not in DATASET_SIGNALS:
            raise ValueError(f"signal={self.signal!r}: one of {', '.join(DATASET_SIGNALS)}")
        if not (self.speed and self.torque):
            raise ValueError("a fault dataset needs the names of the speed and torque inputs")

    @property
    def sensor_settings(self) -> tuple[str, ...]:
        """The sensor settings the signal takes."""
        return DATASET_SIGNALS[self.signal]


@dataclass(frozen=True)
class Capabilities:
    """Optional capabilities of a model class.

    ``frequency_scale``
        The model's time unit is 1 / omega_n for a physical frequency ``model.omega_n``
        [rad/s] (a dimensionless model): sweeps may hold the physical speed
        (``hold="speed"``), and datasets record ``omega_n``.
    ``interpretation``
        The model reads a paper's formulas in one of several ways, ``model.interpretation``
        (recorded in every dataset).
    ``physical_inputs``
        Sweeps and ``with_params`` take the model's physical inputs by name
        (``model.physical_names``) rather than its raw coefficients.
    ``physical_axes``
        The model gives the physical axes of its forcing frequency itself
        (``model.speed_axes(omega)``: mesh frequency, input speed).
    ``paper_device``
        A model of the CATT paper's device (``model.params_in``: its
        :class:`~geardyn.models.params.PlanetaryParams`, read for the mesh frequency of the sun
        gear's teeth and the length scale b_c).
    ``mesh_forces``
        The observables are the meshes' forces: one per entry of ``model.meshes``, in mesh
        order (sweeps report peak and RMS mesh forces, and the dynamic factor where the model
        gives its static mesh forces).
    ``dynamic_factor``
        The model is built from gear geometry under a load, and K_v of ISO 6336-1 applies to
        its meshes (:func:`~geardyn.analysis.dynamic_factor.dynamic_factor_sweep`):
        ``model.input_torque`` [N m] its input torque (a magnitude),
        ``model.at_input_torque(torque)`` the model at another, ``model.kv_groups(torque)`` its
        mesh groups at an input torque (:class:`~geardyn.gears.iso6336_kv.KvMeshGroup`),
        ``model.input_speed_sweep(rpm)`` the swept parameter and its values for input speeds
        [rpm], ``model.mesh_frequency_per_input_speed()`` the reference mesh's order over the
        input speed, and natural frequencies (``natural_frequencies`` in Hz, or in rad/s for a
        model whose time unit is the second). An instance without the needed geometry raises
        :class:`~geardyn.errors.ParameterError` from ``kv_groups``. A one-form
        :class:`~geardyn.UserModel` declares these with
        :class:`~geardyn.DynamicFactorDeclaration` (its natural frequencies in Hz).
    ``natural_frequencies``
        The unit of ``model.natural_frequencies()``, the linearised model's natural
        frequencies (mean stiffness, no backlash), ascending: ``"rad/time"`` (rad per model
        time unit: rad/s for a model in seconds, omega / omega_n for a dimensionless one) or
        ``"Hz"`` (a model of dimensionless time that gives Hz has ``time_scale``, omega_0
        [rad/s], its time unit 1 / omega_0); empty: the model gives none.
    ``stiffness_tables``
        The potential-energy stiffness tables the model carries (the explorer's stiffness
        panel, :func:`geardyn.explore.compute.stiffness_view`): ``"pair"``, one mesh
        (``model.stiffness`` a :func:`~geardyn.gears.potential_energy_stiffness` table over the
        forcing period, ``model.table_phase()``, ``model.stiffness_at(theta, flank)``,
        ``model.n_harmonics``); ``"meshes"``, one per mesh where the instance was built from
        them (``model.mesh_tables`` not None, ``model.period_stiffness(flank)``,
        ``model.faults``, ``model.fourier``); empty: none.
    ``fault_dataset``
        The model's inputs and sensor signal for a labelled fault dataset
        (:class:`FaultDatasetInputs`; None: it makes none). A model whose time is
        dimensionless has ``time_scale``, omega_0 [rad/s] (its time unit is 1 / omega_0).
    """

    frequency_scale: bool = False
    interpretation: bool = False
    physical_inputs: bool = False
    physical_axes: bool = False
    paper_device: bool = False
    mesh_forces: bool = False
    dynamic_factor: bool = False
    natural_frequencies: str = ""
    fault_dataset: FaultDatasetInputs | None = None
    stiffness_tables: str = ""

    def __post_init__(self) -> None:
        if self.dynamic_factor and not (self.mesh_forces and self.natural_frequencies):
            raise ValueError("dynamic_factor needs mesh_forces and natural_frequencies")
        if self.natural_frequencies not in NATURAL_FREQUENCY_UNITS:
            raise ValueError(f"natural_frequencies={self.natural_frequencies!r}: one of "
                             f"{NATURAL_FREQUENCY_UNITS}")
        if self.stiffness_tables not in STIFFNESS_TABLES:
            raise ValueError(f"stiffness_tables={self.stiffness_tables!r}: one of "
                             f"{STIFFNESS_TABLES}")
        ds = self.fault_dataset
        if ds is not None and ds.signal == "mesh_force" and not self.mesh_forces:
            raise ValueError("fault_dataset's mesh_force signal needs mesh_forces")


#: What a model class with the ``dynamic_factor`` capability defines.
DYNAMIC_FACTOR_MEMBERS = ("input_torque", "at_input_torque", "kv_groups", "input_speed_sweep",
                          "mesh_frequency_per_input_speed")

#: The units a model's ``natural_frequencies()`` may be declared in ("" none).
NATURAL_FREQUENCY_UNITS = ("", "rad/time", "Hz")
#: The stiffness tables a model may declare it carries ("" none).
STIFFNESS_TABLES = ("", "pair", "meshes")
