"""A batched split: the flagged slots of a block step split together, lane-vectorised
(issue 34's "located crossings <= 100 ns (flagged slots split together)"), against the scalar
split (``_split_step``) replayed on the same flagged calls.

The batched split runs the iterations of ``_split_step`` in lockstep over up to eight flagged
steps gathered into structure-of-arrays rows (one row of eight per quantity), each phase one
loop over the eight lanes (the model's lane-scalar rhs and events, ``FORM_GENERAL`` as the
split takes them), masked (selects) where a lane is done; the Halley iterations on the
event's cubic in lockstep too. Each lane's arithmetic is ``_split_step``'s, operation for
operation (the forcing phase's two polynomials computed and selected, no branch), so the
states after the split are bitwise the scalar split's. A lane falls back to ``_split_step``
(its inputs kept) where the batch does not follow the scalar path: the phase increment
beyond ``SMALL_ANGLE`` (libm), an interior extremum of an edge function beyond the edge (a
possible graze: the model's event there), two edges to locate in one (sub-)step, a root not
confirmed on the model's event (Illinois), the split limit.

Records the split calls as ``bench/crossing.py`` does (its ``drivers`` and ``collect``: a few
lanes of each model, the steps the screen flags), then replays them in batches of B calls
(``--batch``; consecutive batches take calls of different lanes, round-robin), the scalar
split on the same calls alternating with it, CPU time, median of ``--rounds``: ns per call
and per located crossing, the fraction of calls that fell back, and whether every state,
side, end event and crossing count is bitwise the scalar split's.

Variants (``--variants``): ``general``, the scalar split's arithmetic (the rhs in
``FORM_GENERAL``, both of the forcing phase's polynomials computed and selected); ``short``,
the phase's short polynomials alone (every lane's |Omega h| <= 0.1; the others fall back);
``quiet``, short and the rhs in ``FORM_QUIET`` (the paper lanes' form: bitwise the same
results is checked here, not guaranteed by construction). A batch's lanes are the flagged
calls of different lanes (round-robin); idle lanes of a batch of fewer than eight compute a
copy of its first lane, masked.

    .venv/bin/python bench/split_block.py [--rounds 7] [--batch 1,2,4,8] [--lanes 16]
                                          [--variants general,short,quiet] [--models catt,pair]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numba as nb
import numpy as np

import geardyn
from geardyn.solvers import kernels as kmod

sys.path.insert(0, str(Path(__file__).resolve().parent))
from crossing import collect, drivers, load_record  # noqa: E402

#: Lanes of a batch (one AVX-512 register of doubles).
NV = 8


def _sincos_text(d: str, indent: str, short: bool = False) -> list[str]:
    """Lines computing (sd, cd) = _sincos_small(d), both polynomials, selected (no branch);
    ``short``: the polynomials of |d| <= 0.1 alone (every lane's |Omega h| <= 0.1)."""
    if short:
        return [
            f"{indent}d2 = {d} * {d}",
            f"{indent}sd = {d} * (1.0 + d2 * (-1.0 / 6.0 + d2 * (1.0 / 120.0 + d2 * "
            "(-1.0 / 5040.0 + d2 * (1.0 / 362880.0)))))",
            f"{indent}cd = 1.0 + d2 * (-0.5 + d2 * (1.0 / 24.0 + d2 * (-1.0 / 720.0 + d2 * ("
            "1.0 / 40320.0 + d2 * (-1.0 / 3628800.0)))))",
        ]
    return [
        f"{indent}d2 = {d} * {d}",
        f"{indent}sn1 = {d} * (1.0 + d2 * (-1.0 / 6.0 + d2 * (1.0 / 120.0 + d2 * "
        "(-1.0 / 5040.0 + d2 * (1.0 / 362880.0)))))",
        f"{indent}cs1 = 1.0 + d2 * (-0.5 + d2 * (1.0 / 24.0 + d2 * (-1.0 / 720.0 + d2 * ("
        "1.0 / 40320.0 + d2 * (-1.0 / 3628800.0)))))",
        f"{indent}sn2 = {d} * (1.0 + d2 * (-1.0 / 6.0 + d2 * (1.0 / 120.0 + d2 * (-1.0 / 5040.0"
        " + d2 * (1.0 / 362880.0 + d2 * (-1.0 / 39916800.0 + d2 * (1.0 / 6227020800.0 + d2 * ("
        "-1.0 / 1307674368000.0 + d2 * (1.0 / 355687428096000.0)))))))))",
        f"{indent}cs2 = 1.0 + d2 * (-0.5 + d2 * (1.0 / 24.0 + d2 * (-1.0 / 720.0 + d2 * ("
        "1.0 / 40320.0 + d2 * (-1.0 / 3628800.0 + d2 * (1.0 / 479001600.0 + d2 * ("
        "-1.0 / 87178291200.0 + d2 * (1.0 / 20922789888000.0 + d2 * ("
        "-1.0 / 6402373705728000.0)))))))))",
        f"{indent}sm_ = abs({d}) <= 0.1",
        f"{indent}sd = _pick(sm_, sn1, sn2)",
        f"{indent}cd = _pick(sm_, cs1, cs2)",
    ]


def source(ns: int, ne: int, short: bool = False, form: str = "FORM_GENERAL") -> str:
    """Python source of the batched split for a model of ns states and ne events (lane-scalar
    functions ``_rhs_l``, ``_events_l`` and the tuple helpers of its step core in scope);
    ``short``: the forcing phase's short polynomials alone (see :func:`_sincos_text`);
    ``form``: the lane form of the rhs (the scalar split's: FORM_GENERAL)."""
    # rows of the flat scratch W (NV lanes each, lane m at row * NV + m)
    rows = {}
    off = 0
    for name, n in (("Y", ns), ("YT", ns), ("K1", ns), ("F1", ns), ("Y0", ns), ("G1", ne),
                    ("SD", ne), ("GR", ne), ("NC", ne), ("G0", ne), ("G13", ne), ("G23", ne),
                    ("T0", 1), ("FI", 1), ("FI1", 1), ("H", 1), ("WH", 1), ("SA", 1), ("CA", 1),
                    ("SE", 1), ("CE", 1), ("S0", 1), ("C0", 1), ("U", 1), ("ACT", 1),
                    ("NEED", 1), ("FB", 1), ("JS", 1), ("X", 1), ("A", 1), ("B", 1),
                    ("C0c", 1), ("C1c", 1), ("C2c", 1), ("C3c", 1), ("SJ", 1), ("HD", 1),
                    ("LOC", 1), ("BEY", ne)):
        rows[name] = (off, n)
        off += n
    n_rows = off

    def at(name, q=0):
        return f"W[{(rows[name][0] + q) * NV} + m]"

    def tup(name, n):
        return "(" + "".join(f"{at(name, q)}, " for q in range(n)) + ")"

    def store(name, val, n, cond):
        return [f"{at(name, q)} = _pick({cond}, {val}[{q}], {at(name, q)})" for q in range(n)]

    L = []
    a = L.append
    a(f"N_ROWS = {n_rows}")
    a("")
    # the phase at fraction x of grid step (sa, ca at its start; wh = Omega h, |wh| small)
    a("@nb.njit(inline='always', **_JIT)")
    a("def _pa(sa, ca, wh, x):")
    a("    d = wh * x")
    L.extend(_sincos_text("d", "    ", short))
    a("    return sa * cd + ca * sd, ca * cd - sa * sd")
    a("")
    a("@nb.njit(inline='always', **_JIT)")
    a("def _rk4l(y, h, tm, sm, cm, te, se, ce, k1, PT, m):")
    a("    hh = 0.5 * h")
    a("    k2 = _rhs_l(tm, _t_axpy(y, hh, k1), PT, m, sm, cm, FORM_GENERAL)")
    a("    k3 = _rhs_l(tm, _t_axpy(y, hh, k2), PT, m, sm, cm, FORM_GENERAL)")
    a("    k4 = _rhs_l(te, _t_axpy(y, h, k3), PT, m, se, ce, FORM_GENERAL)")
    a("    return _t_comb(y, rk4_sixth(h), k1, k2, k3, k4)")
    a("")
    a("@nb.njit(inline='always', **_JIT)")
    a("def _extrema(v0, v1, v2, v3):")
    a("    # cubic_extrema with _quadratic_roots, branch-free (the same operations)")
    a("    d1 = v1 - v0")
    a("    d2 = v2 - 2.0 * v1 + v0")
    a("    d3 = v3 - 3.0 * v2 + 3.0 * v1 - v0")
    a("    qa = 0.5 * d3")
    a("    qb = d2 - d3")
    a("    qc = d1 - 0.5 * d2 + d3 / 3.0")
    a("    lin = -qc / qb")
    a("    disc = qb * qb - 4.0 * qa * qc")
    a("    q = -0.5 * (qb + math.copysign(math.sqrt(disc), qb))")
    a("    ra = q / qa")
    a("    rb = qc / q")
    a("    lo = _pick(ra <= rb, ra, rb)")
    a("    hi = _pick(ra <= rb, rb, ra)")
    a("    lo = _pick(q == 0.0, 0.0, lo)")
    a("    hi = _pick(q == 0.0, 0.0, hi)")
    a("    lo = _pick(disc < 0.0, np.nan, lo)")
    a("    hi = _pick(disc < 0.0, np.nan, hi)")
    a("    lo = _pick(qa == 0.0, _pick(qb == 0.0, np.nan, lin), lo)")
    a("    hi = _pick(qa == 0.0, np.nan, hi)")
    a("    r1 = lo")
    a("    r2 = _pick(0.0 < hi < 3.0, hi, np.nan)")
    a("    ok1 = 0.0 < r1 < 3.0")
    a("    s1 = _pick(ok1, r1, r2)")
    a("    s2 = _pick(ok1, r2, np.nan)")
    a("    return (s1 / 3.0, _cubic_at(s1, v0, d1, d2, d3), s2 / 3.0, "
      "_cubic_at(s2, v0, d1, d2, d3))")
    a("")
    a("@nb.njit(inline='always', **_JIT)")
    a("def _sgn(x):")
    a("    return 1.0 if x > 0.0 else -1.0")
    a("")
    # ---- the batched split ----
    a("@nb.njit(_nrt=False, **_JIT_NOALIAS)")
    a("def split_block(nv, W, PT):")
    a('    """Lockstep split of lanes 0..nv-1 of W (ACT = 1: to split); on return FB = 1 where a '
      'lane must be split by _split_step, else Y, SD, G1 hold the split\'s result and NC the '
      'crossings located."""')
    a("    for it in range(MAX_SPLITS):")
    # phase A: k1 (and, it > 0, RK4 to the grid point, events there, need)
    a("        n_need = 0")
    for first in (True, False):
        ind = "                "
        a("        if it == 0:" if first else "        else:")
        a(ind[:-4] + "for m in range(nv):")
        a(f"{ind}act = {at('ACT')} != 0.0")
        a(f"{ind}u = {at('U')}")
        a(f"{ind}h = {at('H')}")
        a(f"{ind}t = {at('T0')} + ({at('FI')} + u) * h")
        a(f"{ind}y = {tup('Y', ns)}")
        a(f"{ind}k1 = _rhs_l(t, y, PT, m, {at('S0')}, {at('C0')}, FORM_GENERAL)")
        L.extend(ind + s for s in store("K1", "k1", ns, "True"))
        gr_any = " | ".join(f"({at('GR', j)} != 0.0)" for j in range(ne))
        a(f"{ind}graze = {gr_any}")
        if first:
            a(f"{ind}g1 = {tup('G1', ne)}")
        else:
            a(f"{ind}dt = (1.0 - u) * h")
            a(f"{ind}sm, cm = _pa({at('SA')}, {at('CA')}, {at('WH')}, 0.5 * (1.0 + u))")
            a(f"{ind}yt = _rk4l(y, dt, t + 0.5 * dt, sm, cm, t + dt, {at('SE')}, "
              f"{at('CE')}, k1, PT, m)")
            L.extend(ind + s for s in store("YT", "yt", ns, "act"))
            a(f"{ind}g1 = _events_l({at('T0')} + {at('FI1')} * h, yt, PT, m, {at('SE')}, "
              f"{at('CE')})")
            L.extend(ind + s for s in store("G1", "g1", ne, "act"))
        a(f"{ind}need = graze")
        for j in range(ne):
            a(f"{ind}need = need | (_sgn(g1[{j}]) != {at('SD', j)})")
        a(f"{ind}need = act & need")
        a(f"{ind}{at('NEED')} = _pick(need, 1.0, 0.0)")
        a(f"{ind}fin = act & (not need)")
        L.extend(ind + s for s in store("Y", tup("YT", ns), ns, "fin"))
        a(f"{ind}{at('ACT')} = _pick(fin, 0.0, {at('ACT')})")
        a(f"{ind}n_need += 1 if need else 0")
    a("        if n_need == 0:")
    a("            return")
    # phase C: f1, the interpolant's events, the screen of each event, the cubic's start
    a("        n_loc = 0")
    for j in range(ne):
        a(f"        ngf{j} = 0")
    a("        for m in range(nv):")
    a(f"            need = {at('NEED')} != 0.0")
    a(f"            u = {at('U')}")
    a(f"            h = {at('H')}")
    a(f"            t = {at('T0')} + ({at('FI')} + u) * h")
    a("            dt = (1.0 - u) * h")
    a("            span = 1.0 - u")
    a(f"            sa = {at('SA')}")
    a(f"            ca = {at('CA')}")
    a(f"            wh = {at('WH')}")
    a(f"            y = {tup('Y', ns)}")
    a(f"            yt = {tup('YT', ns)}")
    a(f"            k1 = {tup('K1', ns)}")
    a(f"            f1 = _rhs_l({at('T0')} + {at('FI1')} * h, yt, PT, m, {at('SE')}, {at('CE')}, "
      "FORM_GENERAL)")
    L.extend("            " + s for s in store("F1", "f1", ns, "True"))
    L.extend("            " + s for s in store("Y0", "y", ns, "True"))
    a("            s, c = _pa(sa, ca, wh, u + 0.0 * span)")
    a("            g0 = _events_l(t, y, PT, m, s, c)")
    a("            h00, h10, h01, h11 = _hermite_weights(dt, 1.0 / 3.0)")
    a("            yb = _t_hermite(y, k1, yt, f1, h00, h10, h01, h11)")
    a("            s, c = _pa(sa, ca, wh, u + 1.0 / 3.0 * span)")
    a("            g13 = _events_l(t + 1.0 / 3.0 * dt, yb, PT, m, s, c)")
    a("            h00, h10, h01, h11 = _hermite_weights(dt, 2.0 / 3.0)")
    a("            yb = _t_hermite(y, k1, yt, f1, h00, h10, h01, h11)")
    a("            s, c = _pa(sa, ca, wh, u + 2.0 / 3.0 * span)")
    a("            g23 = _events_l(t + 2.0 / 3.0 * dt, yb, PT, m, s, c)")
    for nm, v in (("G0", "g0"), ("G13", "g13"), ("G23", "g23")):
        L.extend("            " + s for s in store(nm, v, ne, "True"))
    for j in range(ne):
        a(f"            {at('BEY', j)} = 0.0")
        a(f"            ngf{j} += 1 if (need & ({at('GR', j)} != 0.0)) else 0")
    # the graze test (an interior extremum beyond the edge), per event where a lane needs it
    for j in range(ne):
        a(f"        if ngf{j} > 0:")
        a("            for m in range(nv):")
        a(f"                v0 = {at('G0', j)}")
        a(f"                v1 = {at('G13', j)}")
        a(f"                v2 = {at('G23', j)}")
        a(f"                v3 = {at('G1', j)}")
        a(f"                sj = {at('SD', j)}")
        a("                tol = GRAZE_TOL * max(max(abs(v0), abs(v1)), max(abs(v2), abs(v3)))")
        a("                th1, e1, th2, e2 = _extrema(v0, v1, v2, v3)")
        a("                bey = ((th1 > 0.0) & (sj * e1 < 0.0) & (abs(e1) > tol)) | "
          "((th2 > 0.0) & (sj * e2 < 0.0) & (abs(e2) > tol))")
        a(f"                {at('BEY', j)} = _pick(bey & ({at('GR', j)} != 0.0), 1.0, 0.0)")
    a("        for m in range(nv):")
    a(f"            need = {at('NEED')} != 0.0")
    a(f"            u = {at('U')}")
    a(f"            y = {tup('Y', ns)}")
    a(f"            yt = {tup('YT', ns)}")
    a("            fb = False")
    a("            nl = 0")
    a("            js = -1.0")
    a("            v0s = 0.0")
    a("            v1s = 0.0")
    a("            v2s = 0.0")
    a("            v3s = 0.0")
    a("            sjs = 1.0")
    for j in range(ne):
        a(f"            v0 = {at('G0', j)}")
        a(f"            v1 = {at('G13', j)}")
        a(f"            v2 = {at('G23', j)}")
        a(f"            v3 = {at('G1', j)}")
        a(f"            sj = {at('SD', j)}")
        a("            crossed = _sgn(v3) != sj")
        a(f"            fbj = {at('BEY', j)} != 0.0")
        a("            fb = fb | fbj")
        a("            loc = crossed & (not fbj)")
        a("            nl += 1 if loc else 0")
        a(f"            js = _pick(loc, {float(j)}, js)")
        for v in ("v0", "v1", "v2", "v3", "sj"):
            tgt = "sjs" if v == "sj" else v + "s"
            a(f"            {tgt} = _pick(loc, {v}, {tgt})")
    a("            fb = need & (fb | (nl > 1))")
    a("            loc = need & (not fb) & (nl == 1)")
    a("            none = need & (not fb) & (nl == 0)")
    a(f"            {at('FB')} = _pick(fb, 1.0, {at('FB')})")
    a(f"            {at('ACT')} = _pick(fb | none, 0.0, {at('ACT')})")
    L.extend("            " + s for s in store("Y", "yt", ns, "none"))
    a(f"            {at('LOC')} = _pick(loc, 1.0, 0.0)")
    a(f"            {at('JS')} = js")
    a(f"            {at('SJ')} = sjs")
    a("            c0, c1, c2, c3 = _cubic_coeffs(v0s, v1s, v2s, v3s)")
    a(f"            {at('C0c')} = c0")
    a(f"            {at('C1c')} = c1")
    a(f"            {at('C2c')} = c2")
    a(f"            {at('C3c')} = c3")
    # _cubic_locate's start, b == 1.0
    a("            fa = _forced(c0, sjs)")
    a("            o1 = _sgn(v1s) != sjs")
    a("            o2 = _sgn(v2s) != sjs")
    a("            lo = 0.0 if o1 else (1.0 / 3.0 if o2 else 2.0 / 3.0)")
    a("            flo = fa if o1 else (v1s if o2 else v2s)")
    a("            up = 1.0 / 3.0 if o1 else (2.0 / 3.0 if o2 else 1.0)")
    a("            fup = v1s if o1 else (v2s if o2 else v3s)")
    a("            x = (lo * fup - up * flo) / (fup - flo) if fup != flo else 0.5 * (lo + up)")
    a("            xi = _inverse_cubic(fa, v1s, v2s, v3s)")
    a("            x = xi if lo < xi < up else x")
    a("            x = x if (0.0 < x < 1.0) else 0.5 * (0.0 + 1.0)")
    a(f"            {at('X')} = x")
    a(f"            {at('A')} = 0.0")
    a(f"            {at('B')} = 1.0")
    a(f"            {at('HD')} = _pick(loc, 0.0, 1.0)")
    a("            n_loc += 1 if loc else 0")
    a("        if n_loc > 0:")
    # Halley in lockstep
    a("            for _ in range(60):")
    a("                n_on = 0")
    a("                for m in range(nv):")
    a(f"                    x = {at('X')}")
    a(f"                    aa = {at('A')}")
    a(f"                    bb = {at('B')}")
    a(f"                    c0 = {at('C0c')}")
    a(f"                    c1 = {at('C1c')}")
    a(f"                    c2 = {at('C2c')}")
    a(f"                    c3 = {at('C3c')}")
    a(f"                    sj = {at('SJ')}")
    a(f"                    done = {at('HD')} != 0.0")
    a("                    px = ((c3 * x + c2) * x + c1) * x + c0")
    a("                    zero = px == 0.0")
    a("                    on = _sgn(px) == sj")
    a("                    a2 = x if on else aa")
    a("                    b2 = bb if on else x")
    a("                    dp = (3.0 * c3 * x + 2.0 * c2) * x + c1")
    a("                    d2 = 6.0 * c3 * x + 2.0 * c2")
    a("                    den = 2.0 * dp * dp - px * d2")
    a("                    xn = x - 2.0 * px * dp / den if den != 0.0 else 0.5 * (a2 + b2)")
    a("                    halley = a2 < xn < b2")
    a("                    xn = xn if halley else 0.5 * (a2 + b2)")
    a("                    step = abs(xn - x)")
    a("                    stop = (halley & (step <= HALLEY_TOL)) | (b2 - a2 <= BRACKET_TOL)")
    a("                    upd = (not done) & (not zero)")
    a(f"                    {at('X')} = _pick(upd, xn, x)")
    a(f"                    {at('A')} = _pick(upd, a2, aa)")
    a(f"                    {at('B')} = _pick(upd, b2, bb)")
    a("                    done = done | zero | stop")
    a(f"                    {at('HD')} = _pick(done, 1.0, 0.0)")
    a("                    n_on += 0 if done else 1")
    a("                if n_on == 0:")
    a("                    break")
    # confirm on the model's event, then RK4 to the crossing
    a("            for m in range(nv):")
    a(f"                loc = {at('LOC')} != 0.0")
    a(f"                u = {at('U')}")
    a(f"                h = {at('H')}")
    a(f"                t = {at('T0')} + ({at('FI')} + u) * h")
    a("                dt = (1.0 - u) * h")
    a("                span = 1.0 - u")
    a(f"                sa = {at('SA')}")
    a(f"                ca = {at('CA')}")
    a(f"                wh = {at('WH')}")
    a(f"                x = {at('X')}")
    a(f"                y0 = {tup('Y0', ns)}")
    a(f"                k1 = {tup('K1', ns)}")
    a("                h00, h10, h01, h11 = _hermite_weights(dt, x)")
    a(f"                yb = _t_hermite(y0, k1, {tup('YT', ns)}, {tup('F1', ns)}, h00, h10, "
      "h01, h11)")
    a("                s, c = _pa(sa, ca, wh, u + x * span)")
    a("                g = _events_l(t + x * dt, yb, PT, m, s, c)")
    a(f"                js = {at('JS')}")
    a("                gx = g[0]")
    for j in range(1, ne):
        a(f"                gx = _pick(js == {float(j)}, g[{j}], gx)")
    a(f"                c1 = {at('C1c')}")
    a(f"                c2 = {at('C2c')}")
    a(f"                c3 = {at('C3c')}")
    a("                ok = abs(gx) <= CONFIRM_TOL * abs((3.0 * c3 * x + 2.0 * c2) * x + c1)")
    a("                fb = loc & (not ok)")
    a("                cr = loc & ok")
    a(f"                {at('FB')} = _pick(fb, 1.0, {at('FB')})")
    a(f"                {at('ACT')} = _pick(fb, 0.0, {at('ACT')})")
    a("                theta = x")
    a("                tm = u + 0.5 * theta * (1.0 - u)")
    a("                tu = u + theta * (1.0 - u)")
    a("                sm, cm = _pa(sa, ca, wh, tm)")
    a("                s0, c0 = _pa(sa, ca, wh, tu)")
    a("                hs = theta * dt")
    a("                yn = _rk4l(y0, hs, t + 0.5 * hs, sm, cm, t + hs, s0, c0, k1, PT, m)")
    L.extend("                " + s for s in store("Y", "yn", ns, "cr"))
    for j in range(ne):
        a(f"                fl = cr & (js == {float(j)})")
        a(f"                {at('SD', j)} = _pick(fl, -{at('SD', j)}, {at('SD', j)})")
        a(f"                {at('NC', j)} = _pick(fl, {at('NC', j)} + 1.0, {at('NC', j)})")
    a(f"                {at('U')} = _pick(cr, tu, u)")
    a(f"                {at('S0')} = _pick(cr, s0, {at('S0')})")
    a(f"                {at('C0')} = _pick(cr, c0, {at('C0')})")
    a("                end = cr & (tu >= 1.0)")
    a(f"                ge = _events_l({at('T0')} + {at('FI1')} * h, yn, PT, m, {at('SE')}, "
      f"{at('CE')})")
    L.extend("                " + s for s in store("G1", "ge", ne, "end"))
    a(f"                {at('ACT')} = _pick(end, 0.0, {at('ACT')})")
    # the split limit: the scalar split
    a("    for m in range(nv):")
    a(f"        lim = {at('ACT')} != 0.0")
    a(f"        {at('FB')} = _pick(lim, 1.0, {at('FB')})")
    a(f"        {at('ACT')} = _pick(lim, 0.0, {at('ACT')})")
    return "\n".join(L).replace("FORM_GENERAL", form) + "\n", rows


def build(mod, ns: int, ne: int, short: bool = False, form: str = "FORM_GENERAL"):
    """The batched split for a kernel module's model: (split_block, rows, n_rows, text)."""
    core = sys.modules[mod._split_step.py_func.__module__]
    text, rows = source(ns, ne, short, form)
    env = dict(core.__dict__)
    env["math"] = __import__("math")
    from geardyn.solvers import _step_shared as sh
    for name in ("_cubic_at", "_cubic_coeffs", "_hermite_weights", "_forced", "CONFIRM_TOL",
                 "HALLEY_TOL", "BRACKET_TOL", "GRAZE_TOL", "MAX_SPLITS", "rk4_sixth", "_pick"):
        env[name] = getattr(sh, name)
    env["_inverse_cubic"] = core._inverse_cubic
    from geardyn.core import kernel_source as ksrc
    for name in ("FORM_GENERAL", "FORM_QUIET", "FORM_LOAD"):
        env[name] = getattr(ksrc, name)
    env["_JIT"] = {**core._JIT, "cache": False}
    env["_JIT_NOALIAS"] = {**core._JIT_NOALIAS, "cache": False}
    code = compile(text, "<split_block>", "exec")
    exec(code, env)
    return env["split_block"], rows, env["N_ROWS"], text


def replayers(mod, rows, n_rows, split_block, ns, ne, npar, small):
    """(run_batches, run_scalar): the recorded calls in batches of B gathered into W (the
    rows of :func:`source`), split together (``split_block``), the lanes that fall back by
    ``_split_step``; and the calls one by one by ``_split_step``. Both write every call's
    state, sides, end events and crossings located into the output arrays."""
    split = mod._split_step
    gr_row = mod.GRAZE_ROW

    def r(name, q=0):
        return (rows[name][0] + q) * NV

    RY, RYT, RG1, RSD, RGR, RNC = r("Y"), r("YT"), r("G1"), r("SD"), r("GR"), r("NC")
    RT0, RFI, RFI1, RH, RWH = r("T0"), r("FI"), r("FI1"), r("H"), r("WH")
    RSA, RCA, RSE, RCE, RS0, RC0, RU = r("SA"), r("CA"), r("SE"), r("CE"), r("S0"), r("C0"), \
        r("U")
    RACT, RFB = r("ACT"), r("FB")

    @nb.njit(inline="always")
    def replay_one(r_, P, H, OM, NPER, lane, recs_i, recs_y, recs_g, recs_ph, out_y, out_s,
                   out_g, out_nc, y, y1, side, g1, ncross, work, ybuf, gbuf):
        """Recorded call r_ through the scalar split step, its results into row r_ of out_*."""
        k = lane[r_]
        load_record(r_, recs_y, recs_g, y, y1, side, g1, gbuf, gr_row)
        for j in range(ne):
            ncross[j] = 0
        split(recs_i[r_], 0.0, y, y1, P[k], H[k], OM[k], NPER[k], recs_ph[r_, 0],
              recs_ph[r_, 1], recs_ph[r_, 2], recs_ph[r_, 3], side, g1, ncross, work, ybuf,
              gbuf)
        for q in range(ns):
            out_y[r_, q] = y[q]
        for j in range(ne):
            out_s[r_, j] = side[j]
            out_g[r_, j] = g1[j]
            out_nc[r_, j] = ncross[j]

    @nb.njit(_nrt=False)
    def run_batches(P, H, OM, NPER, lane, order, B, recs_i, recs_y, recs_g, recs_ph, n_rep,
                    out_y, out_s, out_g, out_nc, W, PTb, y, y1, side, g1, ncross, work, ybuf,
                    gbuf):
        n = order.size
        n_fb = 0
        for _ in range(n_rep):
            for b0 in range(0, n, B):
                nb_ = min(B, n - b0)
                for mm in range(NV):  # gather (idle lanes: a copy of the first, not active)
                    r_ = order[b0 + (mm if mm < nb_ else 0)]
                    k = lane[r_]
                    for q in range(ns):
                        W[RY + q * NV + mm] = recs_y[r_, 0, q]
                        W[RYT + q * NV + mm] = recs_y[r_, 1, q]
                    for j in range(ne):
                        W[RSD + j * NV + mm] = recs_g[r_, 0, j]
                        W[RG1 + j * NV + mm] = recs_g[r_, 1, j]
                        W[RGR + j * NV + mm] = recs_g[r_, 2, j]
                        W[RNC + j * NV + mm] = 0.0
                    for j in range(npar):
                        PTb[j, mm] = P[k, j]
                    i = recs_i[r_]
                    h = H[k]
                    W[RT0 + mm] = 0.0
                    W[RFI + mm] = float(i)
                    W[RFI1 + mm] = float(i + 1)
                    W[RH + mm] = h
                    wh = OM[k] * h
                    W[RWH + mm] = wh
                    W[RSA + mm] = recs_ph[r_, 0]
                    W[RCA + mm] = recs_ph[r_, 1]
                    W[RSE + mm] = recs_ph[r_, 2]
                    W[RCE + mm] = recs_ph[r_, 3]
                    W[RS0 + mm] = recs_ph[r_, 0]
                    W[RC0 + mm] = recs_ph[r_, 1]
                    W[RU + mm] = 0.0
                    go = mm < nb_ and abs(wh) <= small
                    W[RACT + mm] = 1.0 if go else 0.0
                    W[RFB + mm] = 0.0 if (go or mm >= nb_) else 1.0
                split_block(NV, W, PTb)
                for mm in range(nb_):
                    r_ = order[b0 + mm]
                    if W[RFB + mm] != 0.0:
                        n_fb += 1
                        replay_one(r_, P, H, OM, NPER, lane, recs_i, recs_y, recs_g, recs_ph,
                                   out_y, out_s, out_g, out_nc, y, y1, side, g1, ncross, work,
                                   ybuf, gbuf)
                    else:
                        for q in range(ns):
                            out_y[r_, q] = W[RY + q * NV + mm]
                        for j in range(ne):
                            out_s[r_, j] = W[RSD + j * NV + mm]
                            out_g[r_, j] = W[RG1 + j * NV + mm]
                            out_nc[r_, j] = W[RNC + j * NV + mm]
        return n_fb

    @nb.njit(_nrt=False)
    def run_scalar(P, H, OM, NPER, lane, order, recs_i, recs_y, recs_g, recs_ph, n_rep, out_y,
                   out_s, out_g, out_nc, y, y1, side, g1, ncross, work, ybuf, gbuf):
        for _ in range(n_rep):
            for r_ in order:
                replay_one(r_, P, H, OM, NPER, lane, recs_i, recs_y, recs_g, recs_ph, out_y,
                           out_s, out_g, out_nc, y, y1, side, g1, ncross, work, ybuf, gbuf)
        return 0

    return run_batches, run_scalar


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--batch", default="1,2,4,8")
    ap.add_argument("--lanes", type=int, default=16)
    ap.add_argument("--calls", type=int, default=200_000, help="split calls per round")
    ap.add_argument("--models", default="catt,pair")
    ap.add_argument("--variants", default="general,short",
                    help="general: as the scalar split (both phase polynomials, FORM_GENERAL);"
                         " short: the short phase polynomials alone (lanes with |Omega h| > 0.1"
                         " fall back); quiet: short and the rhs in FORM_QUIET")
    args = ap.parse_args()
    batches = [int(b) for b in args.batch.split(",")]
    cases = {
        "catt": ("reduced CATT, paper (xi 0.05)",
                 lambda: geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05)),
                 np.linspace(0.3, 4.0, args.lanes)),
        "pair": ("gear pair (zeta 0.05, kappa 0.2, Fm 0.1, Fa 0.2)",
                 lambda: geardyn.GearPair(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2),
                 np.linspace(0.2, 3.0, args.lanes)),
    }
    variants = {"general": (False, "FORM_GENERAL", 0.8), "short": (True, "FORM_GENERAL", 0.1),
                "quiet": (True, "FORM_QUIET", 0.1)}
    chosen = args.variants.split(",")
    print(f"# batched split against _split_step, replayed calls, CPU, median of {args.rounds}")
    print("| case | split | calls | crossings | fallback | ns/call | ns/located crossing | "
          "x scalar | bitwise |")
    print("|---|---|---|---|---|---|---|---|---|")
    for key in args.models.split(","):
        name, make, omegas = cases[key]
        model = make()
        mod = kmod.kernels_for(model.kernel)
        ns = model.initial_state().size
        ne = model.n_events
        t = time.process_time()
        data = collect(model, omegas, 100, 20, ne, 4000, drivers(mod)[0])
        P, H, OM, NPER, lane, ri, ry, rg, rph = data
        npar = P.shape[1]
        runs = {}
        for v in chosen:
            short, form, small = variants[v]
            split_block, rows, n_rows, _ = build(mod, ns, ne, short, form)
            runs[v] = replayers(mod, rows, n_rows, split_block, ns, ne, npar, small)[0]
        run_s = replayers(mod, rows, n_rows, split_block, ns, ne, npar, 0.8)[1]
        n = ri.size
        per = [np.flatnonzero(lane == k) for k in range(len(omegas))]
        rr = []  # round-robin over the lanes: a batch's calls from different lanes
        m = 0
        while len(rr) < n:
            for idx in per:
                if m < idx.size:
                    rr.append(idx[m])
            m += 1
        order = np.array(rr, np.int64)
        W = np.zeros(n_rows * NV)
        PTb = np.zeros((npar, NV))
        work = np.zeros((9, ns))
        ybuf = np.zeros(ns)
        gbuf = mod.event_buffer(0, ne)
        sc = (np.zeros(ns), np.zeros(ns), np.ones(ne, np.int64), np.zeros(ne),
              np.zeros(ne, np.int64))

        def outs(n=n, ns=ns, ne=ne):
            return (np.zeros((n, ns)), np.zeros((n, ne)), np.zeros((n, ne)), np.zeros((n, ne)))

        o_s = outs()
        run_s(P, H, OM, NPER, lane, order, ri, ry, rg, rph, 1, *o_s, *sc, work, ybuf, gbuf)
        keys = [(v, b) for v in chosen for b in batches]
        o_b = {key_: outs() for key_ in keys}
        fbs = {}
        for v, b in keys:
            fbs[v, b] = runs[v](P, H, OM, NPER, lane, order, b, ri, ry, rg, rph, 1, *o_b[v, b],
                                W, PTb, *sc, work, ybuf, gbuf)
        print(f"# {name}: {n} calls recorded (|Omega h| <= 0.1 in {np.mean(OM * H <= 0.1):.0%}"
              f" of the lanes), compile and record {time.process_time() - t:.1f} s CPU",
              flush=True)
        n_cross = int(o_s[3].sum())
        n_rep = max(1, args.calls // n)
        times = {"scalar": []}
        times.update({key_: [] for key_ in keys})
        for _ in range(args.rounds):
            t = time.process_time()
            run_s(P, H, OM, NPER, lane, order, ri, ry, rg, rph, n_rep, *o_s, *sc, work, ybuf,
                  gbuf)
            times["scalar"].append(time.process_time() - t)
            for v, b in keys:
                t = time.process_time()
                runs[v](P, H, OM, NPER, lane, order, b, ri, ry, rg, rph, n_rep, *o_b[v, b], W,
                        PTb, *sc, work, ybuf, gbuf)
                times[v, b].append(time.process_time() - t)
        ts = statistics.median(times["scalar"])
        print(f"| {name} | scalar | {n} | {n_cross} | - | {ts / (n * n_rep) * 1e9:.0f} | "
              f"{ts / (n_cross * n_rep) * 1e9:.0f} | 1.000 | - |")
        for v, b in keys:
            tb = statistics.median(times[v, b])
            same = all(np.array_equal(x, z) for x, z in zip(o_s, o_b[v, b], strict=True))
            print(f"| {name} | {v}, batch {b} | {n} | {int(o_b[v, b][3].sum())} | "
                  f"{fbs[v, b] / n:.2%} | {tb / (n * n_rep) * 1e9:.0f} | "
                  f"{tb / (n_cross * n_rep) * 1e9:.0f} | {tb / ts:.3f} | {same} |", flush=True)


if __name__ == "__main__":
    main()
