"""sha256 of every variable, coordinate and the attrs of faulty potential-energy stiffness
Datasets (root crack, spall, uniform and Archard wear, missing tooth on pinion and wheel, all
at once; helical; internal), to check that two source trees give them bitwise:

    PYTHONPATH=/path/a/src python bench/stiffness_hashes.py a.json
    PYTHONPATH=/path/b/src python bench/stiffness_hashes.py b.json
    python bench/stiffness_hashes.py --compare a.json b.json

``--compare`` lists per case the variables whose hash differs (and those only in b); it
exits 1 if any differs. The faults use only fields every version has (their defaults).
"""

from __future__ import annotations

import hashlib
import json
import sys

import numpy as np

import geardyn
from geardyn.gears import (
    BrokenTooth,
    GearMesh,
    RootCrack,
    Spall,
    SpurGear,
    Wear,
    potential_energy_stiffness,
)
from geardyn.gears.helical import HelicalGear, HelicalMesh, helical_stiffness

M, A, B = 3.2e-3, np.radians(20.0), 0.016
p, w = SpurGear(19, M, A, B, name="pinion"), SpurGear(48, M, A, B, name="wheel")
mesh = GearMesh(p, w)
bores = (0.01, 0.03)
cases = {
    "crack_p": RootCrack("2 mm", tooth=2),
    "crack_w": RootCrack("1.5 mm", gear="wheel", tooth=5),
    "spall_p": Spall("1 mm", "4 mm", "0.3 mm", position="0.5 mm", tooth=1),
    "spall_w": Spall("1.2 mm", "5 mm", "0.2 mm", position="-0.3 mm", gear="wheel", tooth=3),
    "wear_u_p": Wear("10 um", tooth=4),
    "wear_a_w": Wear("20 um", gear="wheel", tooth=7, profile="archard"),
    "wear_a_p": Wear("20 um", tooth=0, profile="archard"),
    "broken_p": BrokenTooth(tooth=6),
    "broken_w": BrokenTooth(gear="wheel", tooth=9),
    "all": (RootCrack("1 mm", tooth=0), Spall("1 mm", "4 mm", "0.3 mm", tooth=3),
            Wear("10 um", gear="wheel", tooth=2), BrokenTooth(gear="wheel", tooth=11)),
}


def digest(ds) -> dict[str, str]:
    """name -> sha256 of values, dims, dtype and attrs; "__attrs__" the Dataset's attrs."""
    out = {}
    for name in list(ds.variables):
        v = ds[name]
        h = hashlib.sha256(np.ascontiguousarray(v.values).tobytes())
        h.update(repr((v.dims, v.dtype.str, sorted(v.attrs.items()))).encode())
        out[name] = h.hexdigest()
    out["__attrs__"] = hashlib.sha256(repr(sorted(ds.attrs.items())).encode()).hexdigest()
    return out


def compare(a_path: str, b_path: str) -> int:
    """Print the differences of two files of :func:`main`; 1 if any hash differs."""
    with open(a_path) as fa, open(b_path) as fb:
        a, b = json.load(fa), json.load(fb)
    bad = 0
    for case, hashes in a.items():
        diff = [n for n in hashes if b.get(case, {}).get(n) != hashes[n]]
        new = sorted(set(b.get(case, {})) - set(hashes))
        bad += bool(diff)
        print(f"{case}: {len(hashes)} hashed, differ: {diff or 'none'}, only in b: {new}")
    return int(bad > 0)


def main(out: str) -> None:
    """Write the hashes of every case to the JSON file ``out``."""
    print(geardyn.__file__, file=sys.stderr)
    res = {}
    for key, f in cases.items():
        res[key] = digest(potential_energy_stiffness(mesh, bore_radius=bores, angles=36,
                                                     cycles=24, faults=f))
    hm = HelicalMesh(HelicalGear(19, M, A, np.radians(15.0), B, name="pinion"),
                     HelicalGear(48, M, A, np.radians(15.0), B, name="wheel"))
    res["helical_wear_crack"] = digest(helical_stiffness(
        hm, bore_radius=bores, angles=24, slices=5, cycles=8,
        faults=(Wear("10 um", tooth=1), RootCrack("1 mm", gear="wheel", tooth=2))))
    im = GearMesh(SpurGear(23, 2e-3, A, 0.02, name="pinion"),
                  SpurGear(71, 2e-3, A, 0.02, name="wheel", internal=True), internal=True)
    res["internal_crack"] = digest(potential_energy_stiffness(
        im, bore_radius=(8e-3, 85e-3), angles=36, cycles=6,
        faults=(RootCrack("1 mm", gear="wheel", tooth=1),
                Spall("1 mm", "4 mm", "0.3 mm", tooth=2))))
    with open(out, "w") as fh:
        json.dump(res, fh, indent=0)


if __name__ == "__main__":
    if sys.argv[1] == "--compare":
        sys.exit(compare(sys.argv[2], sys.argv[3]))
    main(sys.argv[1])
