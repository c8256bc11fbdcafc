"""The interpretations side by side, as a Markdown table generated from the code.

``python -m geardyn.reproduction.tables [PATH]`` rewrites the table between the markers in
``docs/model.md`` (or PATH); ``--check`` only reports whether it is current (exit status 1 if
not). The test suite checks that the table in ``docs/model.md`` is what the code gives now.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

__all__ = ["BEGIN", "END", "generated_section", "interpretation_table", "main", "update"]

BEGIN = "<!-- BEGIN GENERATED: interpretations (python -m geardyn.reproduction.tables) -->"
END = "<!-- END GENERATED: interpretations -->"


def _g(x: float, digits: int = 6) -> str:
    return f"{float(x):.{digits}g}"


def _frequencies(w: np.ndarray) -> str:
    """Distinct natural frequencies with their multiplicity: ``0.6623 (x3), 0.688``."""
    out: list[list[float]] = []
    for v in np.sort(w):
        if out and abs(v - out[-1][0]) <= 1e-9 * max(1.0, abs(v)):
            out[-1][1] += 1
        else:
            out.append([float(v), 1])
    return ", ".join(f"{v:.4f}" + (f" (x{int(n)})" if n > 1 else "") for v, n in out)


def interpretation_table() -> str:
    """The paper's device (Tables 1 and 2, xi1 = xi2 = 0.05) under every interpretation."""
    from geardyn.models.catt import CATTDevice
    from geardyn.models.derived import INTERPRETATIONS
    from geardyn.models.params import PlanetaryParams

    params = PlanetaryParams.paper()
    models = [CATTDevice(params, i) for i in INTERPRETATIONS]
    rows: list[tuple[str, list[str]]] = [
        ("J_c,eff [kg m^2]", [_g(m.derived.J_c_eff) for m in models]),
        ("M_c [kg]", [_g(m.derived.M_c) for m in models]),
        ("omega_n [rad/s]", [_g(m.omega_n) for m in models]),
        ("gamma (carrier damping factor)", [_g(m.derived.gamma, 3) for m in models]),
        ("natural frequencies [omega_n] (multiplicity)",
         [_frequencies(m.natural_frequencies()) for m in models]),
    ]
    for name in ("k_sq_c", "c_sq_c", "k_sq_q", "c_sq_q", "k_pq_q", "k_pq_p", "f_c0", "f_p0"):
        rows.append((f"`{name}`", [_g(np.atleast_1d(m.coefficients[name])[0], 5)
                                   for m in models]))
    rows.append(("static deflection g_sq, g_pq [b_c]",
                 [", ".join(_g(v, 4) for v in m.static_forces()[:2]) for m in models]))
    rows.append(("static mesh force F_sq, F_pq [N]",
                 [", ".join(_g(v, 5) for v in m.static_mesh_forces()[:2]) for m in models]))
    lines = ["| quantity | " + " | ".join(INTERPRETATIONS) + " |",
             "|---|" + "---|" * len(INTERPRETATIONS)]
    lines += [f"| {name} | " + " | ".join(values) + " |" for name, values in rows]
    return "\n".join(lines)


def generated_section() -> str:
    return f"{BEGIN}\n{interpretation_table()}\n{END}"


def _split(text: str, path: Path) -> tuple[str, str, str]:
    if BEGIN not in text or END not in text:
        raise ValueError(f"{path}: the markers {BEGIN!r} and {END!r} are missing")
    head, rest = text.split(BEGIN, 1)
    body, tail = rest.split(END, 1)
    return head, body, tail


def update(path: str | Path, check: bool = False) -> bool:
    """Rewrite the generated table in ``path``; True if it was (``check``: would be) changed."""
    path = Path(path)
    text = path.read_text(encoding="utf-8")
    head, _, tail = _split(text, path)
    new = head + generated_section() + tail
    if new == text:
        return False
    if not check:
        path.write_text(new, encoding="utf-8")
    return True


def main(argv: list[str] | None = None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    check = "--check" in args
    paths = [a for a in args if a != "--check"] or ["docs/model.md"]
    changed = update(paths[0], check=check)
    if check:
        print(f"{paths[0]}: {'out of date' if changed else 'current'}")
        return 1 if changed else 0
    print(f"{paths[0]}: {'updated' if changed else 'already current'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
