"""What a model offers beyond the model interface, declared by the model's class.

Analyses, io and the CLI read :attr:`geardyn.core.model.Model.capabilities` instead of probing
attributes (``hasattr(model, "omega_n")``) or classes (``isinstance(model, CATTDevice)``).
"""

from __future__ import annotations

from dataclasses import dataclass


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
        :class:`~geardyn.errors.ParameterError` from ``kv_groups``.
    ``natural_frequencies``
        The unit of ``model.natural_frequencies()``, the linearised model's natural
        frequencies (mean stiffness, no backlash), ascending: ``"rad/time"`` (rad per model
        time unit: rad/s for a model in seconds, omega / omega_n for a dimensionless one) or
        ``"Hz"``; empty: the model gives none.
    """

    frequency_scale: bool = False
    interpretation: bool = False
    physical_inputs: bool = False
    physical_axes: bool = False
    paper_device: bool = False
    mesh_forces: bool = False
    dynamic_factor: bool = False
    natural_frequencies: str = ""

    def __post_init__(self) -> None:
        if self.dynamic_factor and not (self.mesh_forces and self.natural_frequencies):
            raise ValueError("dynamic_factor needs mesh_forces and natural_frequencies")
        if self.natural_frequencies not in NATURAL_FREQUENCY_UNITS:
            raise ValueError(f"natural_frequencies={self.natural_frequencies!r}: one of "
                             f"{NATURAL_FREQUENCY_UNITS}")


#: What a model class with the ``dynamic_factor`` capability defines.
DYNAMIC_FACTOR_MEMBERS = ("input_torque", "at_input_torque", "kv_groups", "input_speed_sweep",
                          "mesh_frequency_per_input_speed")

#: The units a model's ``natural_frequencies()`` may be declared in ("" none).
NATURAL_FREQUENCY_UNITS = ("", "rad/time", "Hz")
