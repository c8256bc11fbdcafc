"""The planetary gear set's coefficients, declared once (:mod:`geardyn.core.coefficients`): the
header and mesh-block offsets are :mod:`geardyn.models.planetary_kernels`' index constants; the
whole vector (:func:`geardyn.models.planetary.planetary_layout`) places these with the structure
and workspace the kernel reads. The set's physical inputs are declared here too (:data:`INPUTS`,
:mod:`geardyn.core.inputs`)."""

from __future__ import annotations

from geardyn.core.coefficients import Coefficient, CoefficientBlock
from geardyn.core.inputs import N_PLANETS, PhysicalInput


def _d(name: str, unit: str, meaning: str, *inputs: str, constant: str | None = None
       ) -> Coefficient:
    return Coefficient(name, unit, meaning, "derived", inputs, constant=constant)


def structure_entry(name: str, meaning: str, constant: str | None = None) -> Coefficient:
    """A structure entry (constant for the model, never a parameter)."""
    return Coefficient(name, "1", meaning, "structure", constant=constant)


def workspace_entry(name: str, meaning: str, constant: str | None = None) -> Coefficient:
    """A workspace entry (written by the kernel or from other entries, never a parameter)."""
    return Coefficient(name, "1", meaning, "workspace", constant=constant)


_MASSES = ("mass", "inertia_over_r2")
#: The header of the coefficient vector (offsets: :mod:`planetary_kernels`' constants).
HEADER = CoefficientBlock((
    Coefficient("Omega", "1", "forcing frequency / omega_0: the mesh frequency / (mesh_order "
                "omega_0), mesh_order 1 unless a tooth fault makes the period a revolution"),
    structure_entry("n_dof", "number of coordinates"),
    structure_entry("n_meshes", "number of meshes", constant="N_MESH"),
    structure_entry("n_harmonics", "number of stiffness harmonics", constant="N_HARM"),
    workspace_entry("torque_on", "1 where the torque fluctuation F1 is not zero (kernel flag)"),
    Coefficient("torque_order", "1", "order of the input torque fluctuation"),
    Coefficient("torque_phase", "rad", "phase of the input torque fluctuation"),
    workspace_entry("damped", "1 where Ct is not zero (kernel flag)"),
    workspace_entry("two_flank", "1 where a mesh's coast flank differs from its drive flank "
                    "(KF_coast or the coast harmonics; kernel flag)", constant="TWO_FLANK"),
    workspace_entry("multi_order", "1 where a mesh's order differs from 1 (kernel flag)",
                    constant="MULTI_ORDER"),
))
#: Per coordinate d: F0_d, F1_d (names suffixed _d); per pair (a, b): Kt_a_b, Ct_a_b.
FORCES = CoefficientBlock((
    _d("F0", "1", "mean generalised force, M^-1 F / (L omega_0^2)", "sun_torque",
       "ring_torque", "carrier_torque", *_MASSES, "length_scale", "time_scale"),
    _d("F1", "1", "fluctuating generalised force, M^-1 F1 / (L omega_0^2)",
       "torque_fluctuation", "sun_torque", *_MASSES, "length_scale", "time_scale"),
))
MATRICES = CoefficientBlock((
    _d("Kt", "1", "bearing and support stiffness, M^-1 K / omega_0^2", "bearing_stiffness",
       "torsional_stiffness", *_MASSES, "carrier_speed", "time_scale"),
    _d("Ct", "1", "modal damping, M^-1 C / omega_0", "modal_damping", *_MASSES, "time_scale"),
))
#: One mesh block's fixed entries (names prefixed with the mesh's name, s1 .. rN).
MESH = CoefficientBlock((
    _d("b", "1", "backlash half-width / L", "sun_backlash", "ring_backlash", "length_scale",
       constant="M_B"),
    _d("E_s", "1", "transmission error / L, sine part", "sun_mesh_error", "ring_mesh_error",
       "sun_error_phase", "ring_error_phase", "length_scale", constant="M_ES"),
    _d("E_c", "1", "transmission error / L, cosine part", "sun_mesh_error", "ring_mesh_error",
       "sun_error_phase", "ring_error_phase", "length_scale", constant="M_EC"),
    _d("KF", "N", "mesh force per unit deflection X (k_m L)", "sun_mesh_stiffness",
       "ring_mesh_stiffness", "length_scale", constant="M_KF"),
    _d("CF", "N", "mesh force per unit deflection rate X' (c_m L omega_0)", "mesh_damping",
       "sun_mesh_stiffness", "ring_mesh_stiffness", "length_scale", constant="M_CF"),
    _d("KF_coast", "N", "coast-flank mesh force per unit deflection X (k_c,m L), acting where "
       "the deflection is below -b", "sun_coast_stiffness", "ring_coast_stiffness",
       "sun_mesh_stiffness", "ring_mesh_stiffness", "length_scale", constant="M_KFC"),
    Coefficient("order", "1", "the mesh's frequency over the forcing frequency Omega (1: the "
                "forcing mesh's; a gear train's other stages differ)", default=1.0,
                exclusive_minimum=0.0, constant="M_ORDER"),
    structure_entry("radial", "the contact's kind: 0 a dead zone g(x, b) of its own deflection x "
                    "(a mesh, a coupling's backlash); +1 or -1 the x or the y row of a radial "
                    "(circular) clearance of radius b, whose other row is the next (+1) or the "
                    "previous (-1) block: g = (1 - b / r) x for r = sqrt(x^2 + y^2) > b, else 0",
                    constant="M_RADIAL"),
    workspace_entry("harmonics", "the harmonics the kernels sum of this block's series (both "
                    "flanks): its last harmonic whose coefficients are not both zero, at least 1 "
                    "(``n_harmonics`` > 0); 0 (unset) sums all ``n_harmonics``",
                    constant="M_NH"),
    workspace_entry("harmonic_step", "every harmonic of this block's series whose coefficients "
                    "are not both zero is a multiple of it (their greatest common divisor; 1 "
                    "where there is none); the kernels add only those terms; 0 (unset) adds "
                    "every term", constant="M_HSTEP"),
    workspace_entry("harmonic_next", "scratch of the lane-block functions: the next harmonic "
                    "of a stepped series to add", constant="M_HNEXT"),
))
#: Per coordinate d of a mesh: its deflection row W_d and M^-1 W / (L omega_0^2), G_d.
MESH_ROW = CoefficientBlock((
    _d("W", "1", "mesh deflection row", "sun_pressure_angle", "ring_pressure_angle",
       "planet_angles"),
    _d("G", "1/N", "M^-1 W / (L omega_0^2)", "sun_pressure_angle", "ring_pressure_angle",
       "planet_angles", *_MASSES, "length_scale", "time_scale"),
))
CARRIER_SPEED = _d("carrier_speed_tau", "1", "carrier speed Omega_c / omega_0",
                    "carrier_speed", "carrier_speed_ratio", "time_scale")


def harmonics_block(nh: int) -> CoefficientBlock:
    """A mesh's relative-stiffness Fourier coefficients a1, b1, ..., a_nh, b_nh."""
    return CoefficientBlock(tuple(
        _d(f"{ab}{h}", "1", f"{'cosine' if ab == 'a' else 'sine'} part of harmonic {h} of the "
           "relative mesh stiffness", "waveform", "sun_stiffness_fluctuation",
           "ring_stiffness_fluctuation", "sun_mesh_phase", "ring_mesh_phase")
        for h in range(1, nh + 1) for ab in "ab"))


def coast_harmonics_block(nh: int) -> CoefficientBlock:
    """A mesh's coast-flank relative-stiffness Fourier coefficients ac1, bc1, ..., bc_nh (of
    k_c / k_c,mean - 1)."""
    return CoefficientBlock(tuple(
        _d(f"{ab}c{h}", "1", f"{'cosine' if ab == 'a' else 'sine'} part of harmonic {h} of the "
           "relative coast-flank mesh stiffness", "coast_waveform", "waveform",
           "sun_stiffness_fluctuation", "ring_stiffness_fluctuation", "sun_mesh_phase",
           "ring_mesh_phase")
        for h in range(1, nh + 1) for ab in "ab"))


#: The central members (those a set may hold fixed or take as the held member).
CENTRAL = ("carrier", "ring", "sun")
#: The stiffness waveforms a study names (the constructor also takes Fourier coefficients).
WAVEFORMS = ("sine", "rectangular")
#: Most harmonics of a stiffness series: the limit of every model, study table and builder that
#: takes ``harmonics`` (read from :data:`HARMONICS`; the planet count's range is
#: :data:`geardyn.core.inputs.N_PLANETS`, which the gear formulas below the models read too).
MAX_HARMONICS = 200
#: The count ``harmonics`` (of a rectangular waveform's stiffness series), declared once with
#: its range (:meth:`~geardyn.core.inputs.PhysicalInput.count`).
HARMONICS = PhysicalInput("harmonics", "count", "harmonics of the rectangular waveform's series",
                          9, minimum=1, maximum=MAX_HARMONICS)


def _member(name: str, what: str) -> PhysicalInput:
    return PhysicalInput(name, "table", f"the {what} (a geardyn.Member: mass, inertia_over_r2, "
                         "bearing_stiffness, torsional_stiffness, radius)", table="member")


#: The physical inputs of :class:`~geardyn.PlanetaryGearSet` (SI numbers or unit strings),
#: declared once: the ``[params]`` table of a ``planetary`` study is generated from them
#: (:data:`geardyn.io.toml.PlanetaryGearSetParams`), and they are the constructor's keywords
#: (``geometry`` and ``held`` those of :meth:`~geardyn.PlanetaryGearSet.from_geometry`).
INPUTS: tuple[PhysicalInput, ...] = (
    N_PLANETS,
    PhysicalInput("sun_pressure_angle", "angle", "pressure angle of the sun-planet meshes "
                  "[rad, or e.g. \"24.6 deg\"]", "24.6 deg", swept=True),
    PhysicalInput("ring_pressure_angle", "angle", "pressure angle of the ring-planet meshes "
                  "[rad, or e.g. \"24.6 deg\"]", "24.6 deg", swept=True),
    _member("sun", "sun"),
    _member("ring", "ring"),
    _member("carrier", "carrier"),
    _member("planet", "planets (bearing_stiffness: the planet bearing on the carrier)"),
    PhysicalInput("sun_mesh_stiffness", "stiffness", "mean sun-planet mesh stiffness [N/m], "
                  "one or one per planet", form="per_planet", alternative="geometry", swept=True),
    PhysicalInput("ring_mesh_stiffness", "stiffness", "mean ring-planet mesh stiffness [N/m], "
                  "one or one per planet", form="per_planet", alternative="geometry", swept=True),
    PhysicalInput("geometry", "table", "the stage the set is built from "
                  "(PlanetaryGearSet.from_geometry; n_planets and planet_angles place the "
                  "planets), instead of the mesh stiffnesses", table="planetary_geometry",
                  of="from_geometry", alternative="sun_mesh_stiffness"),
    PhysicalInput("planet_angles", "angle", "planet angles psi_n [rad] (default equally "
                  "spaced, psi_n = 2 pi (n - 1) / N)", None, form="list"),
    PhysicalInput("sun_stiffness_fluctuation", "dimensionless", "relative amplitude of the "
                  "sun-planet stiffness fluctuation (half peak-to-peak over the mean), one or "
                  "one per planet", 0.0, form="per_planet", swept=True),
    PhysicalInput("ring_stiffness_fluctuation", "dimensionless", "relative amplitude of the "
                  "ring-planet stiffness fluctuation, one or one per planet", 0.0,
                  form="per_planet", swept=True),
    PhysicalInput("waveform", "choice", "shape of the stiffness fluctuation: \"sine\" or "
                  "\"rectangular\" (contact_ratio, harmonics)", "sine", choices=WAVEFORMS),
    PhysicalInput("contact_ratio", "number", "contact ratio of the rectangular waveform", 1.6,
                  swept=True),
    HARMONICS,
    PhysicalInput("sun_coast_stiffness", "stiffness", "mean coast-flank stiffness of the "
                  "sun-planet meshes [N/m] (None: the drive flank's); not a study key: "
                  "from_geometry sets it", None, form="per_planet", study=False, swept=True),
    PhysicalInput("ring_coast_stiffness", "stiffness", "mean coast-flank stiffness of the "
                  "ring-planet meshes [N/m] (None: the drive flank's); not a study key: "
                  "from_geometry sets it", None, form="per_planet", study=False, swept=True),
    PhysicalInput("coast_waveform", "number", "relative Fourier coefficients of the coast "
                  "flank, a pair (a, b) or {\"sun\": (a, b), \"ring\": (a, b)} (None: the "
                  "drive flank's); not a study key: from_geometry sets it", None, form="list",
                  study=False),
    PhysicalInput("sun_mesh_phase", "angle", "sun-planet mesh phases [rad of the mesh cycle], "
                  "one or one per planet", 0.0, form="per_planet", swept=True),
    PhysicalInput("ring_mesh_phase", "angle", "ring-planet mesh phases [rad of the mesh "
                  "cycle], one or one per planet", 0.0, form="per_planet", swept=True),
    PhysicalInput("sun_backlash", "length", "backlash half-width b of the sun-planet meshes "
                  "[m], one or one per planet", 0.0, form="per_planet", swept=True, explore=True),
    PhysicalInput("ring_backlash", "length", "backlash half-width b of the ring-planet meshes "
                  "[m], one or one per planet", 0.0, form="per_planet", swept=True, explore=True),
    PhysicalInput("sun_mesh_error", "length", "transmission error amplitude of the sun-planet "
                  "meshes [m], one or one per planet", 0.0, form="per_planet", swept=True,
                  explore=True),
    PhysicalInput("ring_mesh_error", "length", "transmission error amplitude of the "
                  "ring-planet meshes [m], one or one per planet", 0.0, form="per_planet",
                  swept=True),
    PhysicalInput("sun_error_phase", "angle", "transmission error phase of the sun-planet "
                  "meshes [rad], one or one per planet", 0.0, form="per_planet", swept=True),
    PhysicalInput("ring_error_phase", "angle", "transmission error phase of the ring-planet "
                  "meshes [rad], one or one per planet", 0.0, form="per_planet", swept=True),
    PhysicalInput("mesh_damping", "dimensionless", "mesh damping ratio zeta_m (c_m = 2 zeta_m "
                  "sqrt(k_m m_e)), one or one per planet", 0.05, form="per_planet", swept=True,
                  explore=True),
    PhysicalInput("modal_damping", "number", "modal damping ratio of every mode of the linear "
                  "model at mean stiffness", 0.0, swept=True),
    PhysicalInput("sun_torque", "torque", "mean torque on the sun [N m] (needs sun.radius)",
                  0.0, swept=True),
    PhysicalInput("ring_torque", "torque", "mean torque on the ring [N m] (needs "
                  "ring.radius)", 0.0, swept=True),
    PhysicalInput("carrier_torque", "torque", "mean torque on the carrier [N m] (needs "
                  "carrier.radius)", 0.0, swept=True),
    PhysicalInput("torque_fluctuation", "number", "relative amplitude A of the sun torque's "
                  "fluctuation T_s (1 + A sin(order Omega tau + phase))", 0.0, swept=True,
                  explore=True),
    PhysicalInput("torque_order", "number", "order of the sun torque's fluctuation (in "
                  "forcing frequencies Omega)", 1.0, swept=True),
    PhysicalInput("torque_phase", "angle", "phase of the sun torque's fluctuation [rad]", 0.0,
                  swept=True),
    PhysicalInput("mesh_frequency", "frequency", "mesh frequency [rad/s] (default omega_0)",
                  None, swept=True),
    PhysicalInput("mesh_order", "count", "mesh cycles per forcing period (1; not a study key: "
                  "from_geometry with faults sets it)", 1, study=False),
    PhysicalInput("rotational_only", "flag", "the purely torsional model (member centres "
                  "fixed)", False),
    PhysicalInput("fixed", "choice", "members held fixed (all their coordinates removed)", (),
                  form="list", choices=CENTRAL),
    PhysicalInput("carrier_speed", "frequency", "carrier speed (rad/s or e.g. \"300 rpm\"; "
                  "\"kinematic\": from the tooth counts of [params.geometry], following the "
                  "input speed): gyroscopic and centripetal terms", None, swept=True),
    PhysicalInput("carrier_speed_ratio", "number", "carrier speed Omega_c / mesh_frequency "
                  "(the carrier speed then follows the mesh frequency in a sweep)", None,
                  swept=True),
    PhysicalInput("centrifugal_preload", "flag", "with a carrier speed: the planets' "
                  "centrifugal load on their bearings, turning with the carrier", True),
    PhysicalInput("held", "choice", "member held in the input_speed kinematics (with "
                  "[params.geometry]; default: the one fixed member, else the ring)", None,
                  choices=CENTRAL, of="from_geometry"),
    PhysicalInput("time_scale", "frequency", "time scale omega_0 [rad/s] (default "
                  "sqrt(sun_mesh_stiffness / planet.inertia_over_r2))", None),
    PhysicalInput("length_scale", "length", "length scale L [m] of the dimensionless "
                  "displacements", 1e-6),
    PhysicalInput("stiffness_gaps", "flag", "whether a mesh may have no pair in contact over "
                  "part of the period (not a study key: from_geometry sets it)", False,
                  study=False),
)
