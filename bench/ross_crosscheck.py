"""The ROSS numbers written into tests/test_published_stiffness.py, recomputed.

ROSS (petrobras/ross, pip ``ross-rotordynamics``; 2.3.0 gave the numbers in the test) is not a
dependency of geardyn: run this with a Python that has it, e.g. a separate virtual environment
(``python -m venv /tmp/rossenv && /tmp/rossenv/bin/pip install ross-rotordynamics "plotly<6"``;
ROSS 2.3.0 failed to import here with plotly 7.1.0, its template naming "scattermapbox"; with
plotly<6 it imports):

    /tmp/rossenv/bin/python bench/ross_crosscheck.py

Prints, as JSON, for each tooth of the test (z = 19, 30, 48, 60, 62) ROSS's four compliances at
the reference circle, the involute part of its bending, shear and axial integrals, its theta_f
and form-circle pressure angle; and for the 62/62 doctest pair and the 19/48 pair the largest,
mean and smallest value of ``Mesh.stiffness_range``. The private methods called
(``_inv_kb``, ``_integrate_invol_term``, ...) are those of ross/gear_element.py in 2.3.0.
"""

from __future__ import annotations

import json
import math
import sys
import warnings

PE_STEEL = dict(E=2.068e11, Poisson=0.3)
#: z: (module [m], face width [m], bore radius [m], ROSS's own steel?)
TEETH = {62: (2e-3, 0.02, 0.0175, True), 19: (3.2e-3, 0.016, 0.012, False),
         48: (3.2e-3, 0.016, 0.035, False), 30: (4e-3, 0.04, 0.0285, False),
         60: (4e-3, 0.04, 0.0575, False)}


def _gear(ge: object, z: int, material: object, pr_angle: float = math.radians(20.0)) -> object:
    m, b, bore, _ = TEETH[z]
    return ge.GearElementTVMS(n=0, material=material, width=b,  # type: ignore[attr-defined]
                              bore_diameter=2.0 * bore, module=m, n_teeth=z,
                              pr_angle=pr_angle)


def _tooth(gear: object) -> dict[str, object]:
    """ROSS's terms of ``gear`` with the contact on the reference circle."""
    g = gear
    beta = g._to_tau(g.pr_angle)  # type: ignore[attr-defined]
    y_op, x_op, _, _ = g._compute_involute_curve(beta)  # type: ignore[attr-defined]
    young, shear_mod = g.material.E, g.material.G_s  # type: ignore[attr-defined]
    c, s = math.cos(beta), math.sin(beta)
    integrands = {
        "bending": lambda a, cc, d: (c * (y_op - cc(a)[0]) - x_op * s) ** 2
        / (young * cc(a)[3]) * d(a),
        "shear": lambda a, cc, d: 1.2 * c * c / (shear_mod * cc(a)[2]) * d(a),
        "axial": lambda a, cc, d: s * s / (young * cc(a)[2]) * d(a),
    }
    return {
        "terms": {name: float(getattr(g, f"_inv_{key}")(beta))
                  for name, key in (("bending", "kb"), ("shear", "ks"), ("axial", "ka"),
                                    ("fillet", "kf"))},
        "involute": {name: float(g._integrate_invol_term(f, beta))  # type: ignore[attr-defined]
                     for name, f in integrands.items()},
        "theta_f": float(g.tooth_dict["root_angle"]),  # type: ignore[attr-defined]
        "alpha_c": float(g.pr_angles_dict["start_point"]),  # type: ignore[attr-defined]
    }


def main() -> int:
    try:
        import ross.gear_element as ge
        from ross.materials import Material, steel
    except ImportError as exc:
        print(f"ROSS is not importable here ({exc}); see this file's docstring", file=sys.stderr)
        return 2
    warnings.filterwarnings("ignore")
    pe = Material(name="pe_steel", rho=7810.0, **PE_STEEL)
    out: dict[str, object] = {}
    for z, (_, _, _, ross_steel) in TEETH.items():
        out[f"tooth_{z}"] = _tooth(_gear(ge, z, steel if ross_steel else pe))
    for name, (z1, z2, material, pr) in {"mesh_62_62": (62, 62, steel, 0.349066),
                                         "mesh_19_48": (19, 48, pe, math.radians(20.0))}.items():
        mesh = ge.Mesh(_gear(ge, z1, material, pr), _gear(ge, z2, material, pr))
        k = [float(v) for v in mesh.stiffness_range]
        out[name] = {"largest": max(k), "mean": sum(k) / len(k), "smallest": min(k)}
    print(json.dumps(out, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
