"""Compiled right-hand side of the Lin & Parker planetary gear set (numba).

Dimensionless form (see :mod:`geardyn.models.planetary`): state ``(X, X')`` with X = q / L the
generalised coordinates over the length scale L and ' = d/dtau, tau = omega_0 t::

    X'' = F0 + F1 sin(r theta + psi) - Kt X - Ct X' - sum_m f_m G_m
    f_m = KF_m k_m(Omega tau) g(W_m . X - e_m, b_m) + CF_m (W_m . X' - e_m')   (g >= 0)
    f_m = KC_m c_m(Omega tau) g(W_m . X - e_m, b_m) + CF_m (W_m . X' - e_m')   (g < 0)

Kt, Ct: the linear (bearing, support) stiffness and the modal damping matrices premultiplied by
M^-1; per mesh m: W_m the deflection row, G_m = M^-1 W_m / (L omega_0^2) [1/N], KF_m and CF_m [N]
the force per unit deflection and deflection rate, k_m the relative stiffness (Fourier series in
the mesh phase), e_m = ES_m sin(theta) + EC_m cos(theta) the transmission error; KC_m and
c_m the same of the coast flank, which acts where the deflection has left the dead zone on the
other side (x < -b). f_m is the dynamic mesh force [N], the observable. Where no mesh's coast
flank differs from its drive flank (the header flag ``TWO_FLANK`` 0) the coast entries are not
read: the arithmetic is the one-flank form's, operation for operation.

A contact may be radial (the block's ``radial`` entry +1 or -1, structure: a gear train's bearing
clearance): two consecutive blocks are the x and the y row of one circular dead zone of radius
b, g = (1 - b / r) x and (1 - b / r) y for r = sqrt(x^2 + y^2) > b, else 0 (each block's g from
both rows' deflections, :func:`radial_zone`; continuous at r = b, its derivative not). Both
blocks' switching functions are r - b and r + b (the pair crosses them together).

theta is the mesh (forcing) phase the solver supplies as ``s, c`` = sin, cos theta (Omega tau
from the start of a run or of a continued lane): the stiffness, the transmission error in the
right-hand side and in the switching functions, and a torque fluctuation of integer order r
(locked to the mesh) all take it (:func:`_torque_wave`). A torque fluctuation of non-integer
order r is a second, incommensurate excitation: its phase is r Omega tau + psi from the time tau
the solver passes (the time since the start of the sweep's chain or of the run).

A mesh's ``order`` r_m (its frequency over Omega; 1 in a planetary set, a gear train's other
stages differ) moves its phase the same way (:func:`_mesh_phase`): theta for r_m = 1 (the
arithmetic above, operation for operation), r_m theta for another integer, r_m Omega tau from
the time tau otherwise (quasi-periodic forcing). The header flag ``MULTI_ORDER`` (1 where a mesh's
order differs from 1) takes the kernels off the shared-stiffness path; the lane-block forms then
take each mesh's own phase and relative stiffnesses from an own-phase cache
(:func:`_lanes_own_phases`: one sin and cos per distinct order, at the two new times of an RK4
step), the values the per-lane functions compute anew.

Coefficient vector: a header (``DAMPED`` is 1 where Ct is not zero), the dof vectors F0, F1, the
matrices Kt, Ct (row-major), one block per mesh (fixed entries, 2 nh Fourier coefficients, W, G, 2
nh coast-flank Fourier coefficients; of these a mesh's sums add only the terms up to its own
harmonic count over the multiples of its harmonic step, the fixed workspace entries
``harmonics`` and ``harmonic_step`` written from the coefficients by :func:`fill_harmonics`,
bitwise the sums of all nh terms), then the *structure* the kernels read
(:func:`fill_structure`, derived from the dense parts): the count nk of the structural entries of
Kt, their rows, columns and values, and per mesh ``MESH_NZ`` dof indices with the W and G values
there (a mesh row touches at most six coordinates: the sun or ring and the planet, three each). So
a right-hand side costs O(nk + n_mesh (MESH_NZ + n_harm)) instead of O(n^2 + n_mesh n): the dense
Kt product and the dense mesh rows are the same sums without their structural zeros, term for term
in the same order (results equal the dense evaluation's). Ct (modal damping) stays dense. A
rotating carrier's Coriolis term -w_c (M^-1 G) X' (``docs/planetary.md``, "Rotating carrier") has
its own structural section at the very end (:func:`_gyro_offset`), so that Ct stays the same in
every lane of a sweep in which the carrier speed w_c follows the mesh frequency.

The ``*_lanes`` forms evaluate the same arithmetic, operation for operation, on a block of lanes
in structure-of-arrays layout (state Y[q, k], coefficients PT[j, k], the forcing phase S[k],
C[k]; SC: >= 2 scratch rows) for the sweep kernel; the structure (indices) is the same in every
lane of a sweep (it depends only on inputs that are not swept). The vector carries the rows
of a relative-stiffness cache (:func:`cache_entries`) before the gyroscopic section and those of
the own-phase cache (:func:`own_cache_names`) at its end, workspace of the lane-block functions
in the block's own copy PT (:func:`_lanes_cached_stiffness`, :func:`_lanes_own_phases`).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from geardyn._jit_target import WidthCompiler
from geardyn.models.elements import dead_zone, harmonic_clip, harmonic_factor, harmonic_turn
from geardyn.models.planetary_coefficients import HEADER as HEADER_BLOCK
from geardyn.models.planetary_coefficients import MESH

# Index constants: the offsets of the declared coefficients (geardyn.models.planetary_coefficients)
# header
_H = HEADER_BLOCK.offset
OMEGA, N_DOF, N_MESH, N_HARM = _H("Omega"), _H("n_dof"), _H("n_meshes"), _H("n_harmonics")
TORQUE_ON, TORQUE_ORDER = _H("torque_on"), _H("torque_order")
TORQUE_PHASE, DAMPED = _H("torque_phase"), _H("damped")
TWO_FLANK, MULTI_ORDER = _H("two_flank"), _H("multi_order")
HEADER = HEADER_BLOCK.size
# mesh block fixed entries
_M = MESH.offset
M_B, M_ES, M_EC, M_KF, M_CF = _M("b"), _M("E_s"), _M("E_c"), _M("KF"), _M("CF")
M_KFC, M_ORDER, M_RADIAL, M_NH = _M("KF_coast"), _M("order"), _M("radial"), _M("harmonics")
M_HSTEP, M_HNEXT = _M("harmonic_step"), _M("harmonic_next")
MESH_FIXED = MESH.size
#: Structural entries per mesh row in the structure section (padded with zero weights).
MESH_NZ = 6
#: Entries of the lane-block functions' relative-stiffness cache (each: the key, then the drive
#: and the coast relative stiffness of every mesh), and the key of an empty one (no sine or
#: cosine equals it).
CACHE_ENTRIES = 2
EMPTY = 2.0
#: Entries of the lane-block functions' own-phase cache (:func:`_lanes_own_phases`): each the
#: key (time, sin and cos of the forcing phase), then the sin and cos of every mesh's own phase
#: and its drive and coast relative stiffness there. All zero is empty (no phase has sin and
#: cos 0).
OWN_ENTRIES = 2
#: The last rows of the cache section, 0 in a freshly loaded slot: the lane-block rhs then checks
#: whether the block's lanes share one Ct (:func:`_lanes_ct_uniform`), and the lane-block
#: functions take the block's harmonic counts and steps anew (:func:`_lanes_prepare_harmonics`).
CT_ROWS = 2

_JIT = {"cache": True, "error_model": "numpy", "boundscheck": False,
        "pipeline_class": WidthCompiler}
#: The lane-block functions allocate nothing: compiled without reference counting (the kernels
#: call them, once per block step, rather than inline them).
_JIT_LANES = {**_JIT, "_nrt": False}
#: The bodies the entry points call (:func:`_rhs_body`, :func:`_events_body`), the per-lane
#: mesh forces (:func:`_mesh_forces_shared`, :func:`_mesh_force`) and the lane-block forms'
#: stiffness series and own-phase cache (:func:`_lanes_stiffness`, :func:`_lanes_own_phases`):
#: called, not inlined, and without reference counting (they allocate nothing), so that each
#: is compiled once per argument types and appears once in a kernel, however many call sites
#: the kernel templates inline the entry points at (the kernels inline ``planetary_rhs`` and
#: ``planetary_events`` at every call site: a call of the body each). ``forceinline`` False
#: explicitly: numba's flag is inherited from the compile a function is first compiled in,
#: and the templates compile the entry points with it (LLVM's ``alwaysinline``), which would
#: make LLVM inline a body at every call site of every kernel function (the split step's
#: ~14 copies of the right-hand side).
_JIT_BODY = {**_JIT_LANES, "forceinline": False}
#: The lane-block mesh loop (:func:`_lanes_meshes`): typed and lowered once, for both its
#: callers (``planetary_rhs_lanes``, ``planetary_observe_lanes``), and inlined by LLVM into
#: each (``forceinline``; called, ``planetary_rhs_lanes`` was slower).
_JIT_INL = {**_JIT_LANES, "forceinline": True}


def layout(n: int, n_mesh: int, nh: int, nk: int = 0, ng: int = 0) -> dict[str, int]:
    """Offsets of the parts of the coefficient vector for n dofs, n_mesh meshes, nh harmonics,
    nk structural entries of Kt and ng of the gyroscopic matrix (:func:`_gyro_offset`)."""
    f0 = HEADER
    f1 = f0 + n
    kt = f1 + n
    ct = kt + n * n
    mesh = ct + n * n
    bs = block_size(n, nh)
    st = mesh + n_mesh * bs
    mz = st + 1 + 3 * nk
    cache = mz + n_mesh * 3 * MESH_NZ
    gyro = cache + 1 + CACHE_ENTRIES * (2 + 2 * n_mesh) + CT_ROWS
    own = gyro + 2 + 3 * ng
    return {"F0": f0, "F1": f1, "Kt": kt, "Ct": ct, "mesh": mesh, "block": bs,
            "structure": st, "mesh_nz": mz, "cache": cache, "gyro": gyro, "own": own,
            "size": own + 3 + OWN_ENTRIES * (3 + 4 * n_mesh)}


@nb.njit(inline="always", **_JIT)
def block_size(n, nh):
    """Entries of one mesh block: the fixed ones, 2 nh drive coefficients, W and G (n each),
    2 nh coast coefficients."""
    return MESH_FIXED + 4 * nh + 2 * n


@nb.njit(inline="always", **_JIT)
def coast_offset(n, nh):
    """Offset of the coast-flank coefficients in a mesh block."""
    return MESH_FIXED + 2 * nh + 2 * n


def gyro_names(dofs: tuple[str, ...], entries: list[tuple[int, int]]) -> list[str]:
    """Names of the gyroscopic section: the carrier speed Omega_c / omega_0, the count, then
    the rows, columns and values of M^-1 G (see :func:`_gyro_offset`)."""
    ng = len(entries)
    return (["carrier_speed_tau", "n_gyro"] + [f"gyro_row{e}" for e in range(ng)]
            + [f"gyro_col{e}" for e in range(ng)]
            + [f"gyro_{dofs[i]}_{dofs[j]}" for i, j in entries])


def cache_entries(n_mesh: int) -> tuple[list[str], list[float]]:
    """Names and initial values of the stiffness cache rows (see :func:`_lanes_cached_stiffness`):
    the entry used last, then per entry the forcing phase (sin, cos; 2.0: empty) and the
    drive and the coast relative stiffness of every mesh there. Workspace of the lane-block
    functions, not inputs."""
    names = ["cache_last"]
    values = [0.0]
    for e in range(CACHE_ENTRIES):
        names += [f"cache{e}_sin", f"cache{e}_cos"] + [f"cache{e}_k{m}" for m in range(n_mesh)]
        names += [f"cache{e}_kc{m}" for m in range(n_mesh)]
        values += [EMPTY, EMPTY] + [0.0] * (2 * n_mesh)
    return names + ["cache_ct_checked", "cache_harmonics_checked"], values + [0.0, 0.0]


def own_cache_names(n_mesh: int) -> list[str]:
    """Names of the own-phase cache rows (:func:`_lanes_own_phases`; workspace, initially 0:
    empty): the entry used last, two scratch rows, then per entry its key (the time, sin and
    cos of the forcing phase) and per mesh the sin and cos of its own phase, its drive and
    coast relative stiffness."""
    names = ["own_last", "own_scratch_cos", "own_scratch_sin"]
    for e in range(OWN_ENTRIES):
        names += [f"own{e}_t", f"own{e}_sin", f"own{e}_cos"]
        for part in ("sin", "cos", "k", "kc"):
            names += [f"own{e}_{part}{m}" for m in range(n_mesh)]
    return names


def structure_names(dofs: tuple[str, ...], mesh_names: tuple[str, ...],
                    kt_entries: list[tuple[int, int]]) -> list[str]:
    """Names of the structure section's entries (derived coefficients, see the module doc)."""
    nk = len(kt_entries)
    out = ["nk"] + [f"Kt_row{e}" for e in range(nk)] + [f"Kt_col{e}" for e in range(nk)]
    out += [f"Kt_nz_{dofs[i]}_{dofs[j]}" for i, j in kt_entries]
    for m in mesh_names:
        out += [f"{m}_nz_index{j}" for j in range(MESH_NZ)]
        out += [f"{m}_nz_W{j}" for j in range(MESH_NZ)] + [f"{m}_nz_G{j}" for j in range(MESH_NZ)]
    return out


def fill_structure(P: np.ndarray, kt_entries: list[tuple[int, int]],
                   mesh_dofs: list[list[int]]) -> None:
    """Write the structure section of every row of ``P`` (lanes x size, in place) from its dense
    parts: the Kt entries ``kt_entries`` (row-major order) and per mesh the dofs ``mesh_dofs[m]``
    (ascending, at most ``MESH_NZ``); and every mesh block's harmonic count and step
    (:func:`fill_harmonics`). A dense Kt, W or G entry outside the structure that is not zero
    (e.g. a raw coefficient override) is a ``ValueError``."""
    P = np.atleast_2d(P)
    n, nm, nh = int(P[0, N_DOF]), int(P[0, N_MESH]), int(P[0, N_HARM])
    nk = len(kt_entries)
    lay = layout(n, nm, nh, nk)
    st = lay["structure"]
    K = P[:, lay["Kt"]:lay["Kt"] + n * n].reshape(-1, n, n)
    inside = np.zeros((n, n), bool)
    for i, j in kt_entries:
        inside[i, j] = True
    if np.any(K[:, ~inside] != 0.0):
        raise ValueError("a Kt entry outside the gear set's structure is not zero; the kernel "
                         "reads only the structural entries")
    P[:, st] = nk
    P[:, st + 1:st + 1 + nk] = [i for i, _ in kt_entries]
    P[:, st + 1 + nk:st + 1 + 2 * nk] = [j for _, j in kt_entries]
    P[:, st + 1 + 2 * nk:st + 1 + 3 * nk] = K[:, [i for i, _ in kt_entries],
                                              [j for _, j in kt_entries]]
    f = MESH_FIXED + 2 * nh
    for m, dofs in enumerate(mesh_dofs):
        if len(dofs) > MESH_NZ or list(dofs) != sorted(set(dofs)):
            raise ValueError(f"mesh {m}: at most {MESH_NZ} ascending dofs (got {dofs})")
        o = lay["mesh"] + m * lay["block"]
        W = P[:, o + f:o + f + n]
        G = P[:, o + f + n:o + f + 2 * n]
        out = np.ones(n, bool)
        out[list(dofs)] = False
        if np.any(W[:, out] != 0.0) or np.any(G[:, out] != 0.0):
            raise ValueError(f"mesh {m}: a W or G entry outside the gear set's structure is "
                             "not zero; the kernel reads only the structural entries")
        q = lay["mesh_nz"] + m * 3 * MESH_NZ
        k = len(dofs)
        P[:, q:q + 3 * MESH_NZ] = 0.0  # padding: index 0, zero weights
        P[:, q:q + k] = dofs
        P[:, q + MESH_NZ:q + MESH_NZ + k] = W[:, list(dofs)]
        P[:, q + 2 * MESH_NZ:q + 2 * MESH_NZ + k] = G[:, list(dofs)]
    fill_harmonics(P)


def fill_harmonics(P: np.ndarray) -> None:
    """Write every mesh block's ``harmonics`` and ``harmonic_step`` entries in every row of
    ``P`` (lanes x size, in place) from the row's own Fourier coefficients: the last harmonic h
    (1 .. nh) whose drive or coast coefficients are not both zero, at least 1 (0 where nh is
    0), and the greatest common divisor of those harmonics (1 where there is none). The kernels
    sum a block's series up to its count and, past the first harmonic, only the multiples of
    its step (:func:`_harmonics`, :func:`_step`): every term left out has zero coefficients,
    so leaving it out changes no sum's bits (x + (+-0) is x for x != 0, and a zero for a zero
    x, so the partial sums with and without it are equal or both zeros; the next nonzero term
    and 1 + acc give the same value from either zero). The recurrence of cos h theta and
    sin h theta still runs over every h, so the terms kept are the same values."""
    P = np.atleast_2d(P)
    n, nm, nh = int(P[0, N_DOF]), int(P[0, N_MESH]), int(P[0, N_HARM])
    lay = layout(n, nm, nh)
    for m in range(nm):
        o = lay["mesh"] + m * lay["block"]
        if nh == 0:
            P[:, o + M_NH] = 0.0
            P[:, o + M_HSTEP] = 1.0
            continue
        d = P[:, o + MESH_FIXED:o + MESH_FIXED + 2 * nh].reshape(-1, nh, 2)
        c0 = o + coast_offset(n, nh)
        c = P[:, c0:c0 + 2 * nh].reshape(-1, nh, 2)
        nonzero = np.any(d != 0.0, axis=2) | np.any(c != 0.0, axis=2)
        last = np.where(nonzero.any(axis=1), nh - np.argmax(nonzero[:, ::-1], axis=1), 0)
        P[:, o + M_NH] = np.maximum(last, 1)
        P[:, o + M_HSTEP] = np.maximum(np.gcd.reduce(
            np.where(nonzero, np.arange(1, nh + 1), 0), axis=1), 1)


@nb.njit(inline="always", **_JIT)
def _offsets(p):
    """n, n_mesh, nh, the mesh blocks' offset and size, the structure's and its mesh part's."""
    n = int(p[N_DOF])
    nm = int(p[N_MESH])
    nh = int(p[N_HARM])
    mesh = HEADER + 2 * n + 2 * n * n
    bs = block_size(n, nh)
    st = mesh + nm * bs
    mz = st + 1 + 3 * int(p[st])
    return n, nm, nh, mesh, bs, st, mz


@nb.njit(inline="always", **_JIT)
def _harmonics(p, o, nh):
    """The harmonics summed of the mesh block at o (both flanks): its ``harmonics`` entry
    (:func:`fill_harmonics`), or all nh where that is unset (0) or not below nh."""
    h = int(p[o + M_NH])
    return h if 0 < h < nh else nh


@nb.njit(inline="always", **_JIT)
def _lanes_harmonics(PT, nl, o, nh):
    """The most harmonics :func:`_harmonics` gives the mesh block at o in a lane of the block:
    every lane's sum runs that far (a lane's terms past its own count are zeros)."""
    top = 0
    for k in range(nl):
        h = int(PT[o + M_NH, k])
        h = h if 0 < h < nh else nh
        top = max(top, h)
    return top


@nb.njit(inline="always", **_JIT)
def _step(p, o):
    """The harmonic step of the mesh block at o: its ``harmonic_step`` entry
    (:func:`fill_harmonics`), 1 where that is unset (0)."""
    s = int(p[o + M_HSTEP])
    return s if s > 1 else 1


@nb.njit(inline="always", **_JIT)
def _lanes_step(PT, nl, o):
    """The greatest common divisor of the harmonic steps (:func:`_step`) of the mesh block at o
    in the block's lanes: a step every lane's series keeps."""
    g = 0
    for k in range(nl):
        a = int(PT[o + M_HSTEP, k])
        a = a if a > 1 else 1
        while a != 0:
            g, a = a, g % a
    return g


@nb.njit(inline="always", **_JIT)
def _stepped_factor(p, f, nh, step, s, c):
    """:func:`~geardyn.models.elements.harmonic_factor` that adds, past the first harmonic, only
    the terms of the harmonics that are multiples of ``step`` (the recurrence runs over every
    harmonic: the terms added are the same values); ``harmonic_factor`` itself for step 1."""
    if step == 1 or nh == 0:
        return harmonic_factor(p, f, nh, s, c)
    acc = p[f] * c + p[f + 1] * s
    ch = c
    sh = s
    nxt = step - 1
    for h in range(1, nh):
        ch, sh = harmonic_turn(ch, sh, c, s)
        if h == nxt:
            acc += p[f + 2 * h] * ch + p[f + 2 * h + 1] * sh
            nxt += step
    return harmonic_clip(1.0 + acc)


@nb.njit(inline="always", **_JIT)
def _gyro_offset(nm, mz):
    """Offset of the gyroscopic section, after the cache: the carrier speed w_c = Omega_c /
    omega_0, the count ng, then ng rows, columns and values of M^-1 G (the Coriolis term is
    -w_c (M^-1 G) X' in X''); structural, so the same in every lane of a sweep, while w_c may
    differ per lane (a carrier speed that follows the mesh frequency)."""
    return mz + nm * 3 * MESH_NZ + 1 + CACHE_ENTRIES * (2 + 2 * nm) + CT_ROWS


@nb.njit(inline="always", **_JIT)
def _own_offset(PT, nm, mz):
    """Offset of the own-phase cache section (:func:`_lanes_own_phases`), after the gyroscopic
    section (its count in row 1 of that section, column 0)."""
    g = _gyro_offset(nm, mz)
    return g + 2 + 3 * int(PT[g + 1, 0])


@nb.njit(inline="always", **_JIT)
def _mesh_phase(t, order, omega, s, c):
    """sin, cos and rate of a mesh's phase: the forcing phase (s, c; rate omega) for order 1;
    order theta for another integer order (locked to the forcing phase theta); order omega t
    otherwise (from the time t, as :func:`_torque_wave`: quasi-periodic forcing)."""
    if order == 1.0:
        return s, c, omega
    if order == math.floor(order):
        th = order * math.atan2(s, c)
    else:
        th = order * omega * t
    return math.sin(th), math.cos(th), order * omega


@nb.njit(inline="always", **_JIT)
def _mesh_state(y, p, o, q, n, s, c, om):
    """Deflection minus error and its rate (W . X - e, W . X' - e') of the mesh block at o, its
    structure at q, at the mesh phase s, c turning at om."""
    d = 0.0
    v = 0.0
    for j in range(MESH_NZ):
        i = int(p[q + j])
        w = p[q + MESH_NZ + j]
        d += w * y[i]
        v += w * y[n + i]
    d -= p[o + M_ES] * s + p[o + M_EC] * c
    v -= om * (p[o + M_ES] * c - p[o + M_EC] * s)
    return d, v


@nb.njit(inline="always", **_JIT)
def radial_zone(x, r, b):
    """The radial dead zone's component along x: (1 - b / r) x for r > b, else 0 (r the
    radius sqrt(x^2 + y^2) of the deflection, b the clearance); continuous at r = b."""
    if r > b:
        return (1.0 - b / r) * x
    return 0.0


@nb.njit(inline="always", **_JIT)
def _radius(d, dp, kind):
    """r = sqrt(x^2 + y^2) of a radial contact from its row's deflection d and its other row's
    dp, x first (``kind`` +1: d is x), so that both rows get the same r bitwise."""
    if kind > 0.0:
        return math.sqrt(d * d + dp * dp)
    return math.sqrt(dp * dp + d * d)


@nb.njit(inline="always", **_JIT)
def _zone(y, p, o, q, n, bs, d, s, c, om):
    """The contact's g at its deflection d (block at o, structure at q): the dead zone g(d, b),
    or for a radial contact (``radial`` +-1) its component of the radial dead zone, with its
    other row's deflection from the block ``radial`` blocks away (:func:`radial_zone`)."""
    kind = p[o + M_RADIAL]
    if kind == 0.0:
        return dead_zone(d, p[o + M_B])
    j = int(kind)
    dp, _ = _mesh_state(y, p, o + j * bs, q + j * 3 * MESH_NZ, n, s, c, om)
    return radial_zone(d, _radius(d, dp, kind), p[o + M_B])


@nb.njit(**_JIT_BODY)
def _mesh_force(t, y, p, o, q, n, nh, s, c):
    """The dynamic mesh force [N] of the mesh block at o (structure at q): its own phase
    (:func:`_mesh_phase`), its dead zone (:func:`_zone`) and the flank its output is on."""
    s, c, om = _mesh_phase(t, p[o + M_ORDER], p[OMEGA], s, c)
    d, v = _mesh_state(y, p, o, q, n, s, c, om)
    g = _zone(y, p, o, q, n, block_size(n, nh), d, s, c, om)
    if g < 0.0 and p[TWO_FLANK] != 0.0:  # the coast flank
        kc = _stepped_factor(p, o + coast_offset(n, nh), _harmonics(p, o, nh), _step(p, o),
                             s, c)
        return p[o + M_KFC] * kc * g + p[o + M_CF] * v
    k = _stepped_factor(p, o + MESH_FIXED, _harmonics(p, o, nh), _step(p, o), s, c)
    return p[o + M_KF] * k * g + p[o + M_CF] * v


@nb.njit(**_JIT_BODY)
def _mesh_forces_shared(y, out, p, n, nm, nh, mesh, bs, mz, s, c):
    """The mesh forces into out[:nm]: :func:`_mesh_force` of every mesh with one harmonic
    recurrence for all (the same operations per mesh, each mesh's sum to its own harmonic
    count :func:`_harmonics` over the multiples of its step :func:`_step`; the relative
    stiffnesses first, in out, clipped at 0 by
    :func:`~geardyn.models.elements.harmonic_clip`)."""
    for m in range(nm):
        out[m] = 1.0
    if nh > 0:
        top = 0
        for m in range(nm):
            f = mesh + m * bs + MESH_FIXED
            out[m] = p[f] * c + p[f + 1] * s
            top = max(top, _harmonics(p, mesh + m * bs, nh))
        ch = c
        sh = s
        for h in range(1, top):
            ch, sh = harmonic_turn(ch, sh, c, s)
            for m in range(nm):
                o = mesh + m * bs
                st = _step(p, o)
                if h < _harmonics(p, o, nh) and (st == 1 or (h + 1) % st == 0):
                    f = o + MESH_FIXED + 2 * h
                    out[m] += p[f] * ch + p[f + 1] * sh
        for m in range(nm):
            out[m] = harmonic_clip(1.0 + out[m])
    for m in range(nm):
        o = mesh + m * bs
        q = mz + m * 3 * MESH_NZ
        d, v = _mesh_state(y, p, o, q, n, s, c, p[OMEGA])
        out[m] = p[o + M_KF] * out[m] * _zone(y, p, o, q, n, bs, d, s, c, p[OMEGA]) \
            + p[o + M_CF] * v


@nb.njit(inline="always", **_JIT)
def _torque_wave(t, order, omega, phase, s, c):
    """sin of the torque fluctuation's phase: order theta + phase for an integer order, theta
    the mesh phase with sine s and cosine c (locked to the mesh); order omega t + phase
    otherwise (from the time t)."""
    if order == math.floor(order):
        return math.sin(order * math.atan2(s, c) + phase)
    return math.sin(order * omega * t + phase)


@nb.njit(**_JIT)
def planetary_rhs(t, y, dy, p, s, c):
    """dy/dt of the planetary gear set (dimensionless): :func:`_rhs_body`."""
    _rhs_body(t, y, dy, p, s, c)


@nb.njit(**_JIT_BODY)
def _rhs_body(t, y, dy, p, s, c):
    """dy/dt of the planetary gear set (dimensionless)."""
    n, nm, nh, mesh, bs, st, mz = _offsets(p)
    fl = 0.0
    if p[TORQUE_ON] != 0.0:
        fl = _torque_wave(t, p[TORQUE_ORDER], p[OMEGA], p[TORQUE_PHASE], s, c)
    # the mesh forces first, into dy[:nm] (scratch until the end); per mesh with two flanks
    shared = nm <= n and p[TWO_FLANK] == 0.0 and p[MULTI_ORDER] == 0.0
    if shared:
        _mesh_forces_shared(y, dy, p, n, nm, nh, mesh, bs, mz, s, c)
    f1 = HEADER + n
    for i in range(n):
        dy[n + i] = p[HEADER + i] + p[f1 + i] * fl
    nk = int(p[st])
    for e in range(nk):
        dy[n + int(p[st + 1 + e])] -= p[st + 1 + 2 * nk + e] * y[int(p[st + 1 + nk + e])]
    if p[DAMPED] != 0.0:  # modal damping: the dense Ct product (skipped when Ct = 0)
        ct = HEADER + 2 * n + n * n
        for i in range(n):
            acc = dy[n + i]
            r = ct + i * n
            for j in range(n):
                acc -= p[r + j] * y[n + j]
            dy[n + i] = acc
    g = _gyro_offset(nm, mz)
    wc = p[g]
    if wc != 0.0:  # the rotating carrier's Coriolis term (structural entries)
        ng = int(p[g + 1])
        for e in range(ng):
            j = n + int(p[g + 2 + ng + e])
            dy[n + int(p[g + 2 + e])] -= (wc * p[g + 2 + 2 * ng + e]) * y[j]
    for m in range(nm):
        q = mz + m * 3 * MESH_NZ
        f = dy[m] if shared else _mesh_force(t, y, p, mesh + m * bs, q, n, nh, s, c)
        for j in range(MESH_NZ):
            dy[n + int(p[q + j])] -= f * p[q + 2 * MESH_NZ + j]
    for i in range(n):
        dy[i] = y[n + i]


@nb.njit(**_JIT)
def planetary_events(t, y, g, p, s, c):
    """Dead-zone edges: x_m - b_m and x_m + b_m of every mesh (x_m = W_m . X - e_m, the error
    at the mesh's phase, :func:`_mesh_phase`); x_m is the radius r of a radial contact (both
    its rows: r - b, r + b). :func:`_events_body`."""
    _events_body(t, y, g, p, s, c)


@nb.njit(**_JIT_BODY)
def _events_body(t, y, g, p, s, c):
    """:func:`planetary_events`."""
    n, nm, nh, mesh, bs, st, mz = _offsets(p)
    for m in range(nm):
        o = mesh + m * bs
        q = mz + m * 3 * MESH_NZ
        sm, cm, om = _mesh_phase(t, p[o + M_ORDER], p[OMEGA], s, c)
        d, _ = _mesh_state(y, p, o, q, n, sm, cm, om)
        kind = p[o + M_RADIAL]
        if kind != 0.0:
            j = int(kind)
            dp, _ = _mesh_state(y, p, o + j * bs, q + j * 3 * MESH_NZ, n, sm, cm, om)
            d = _radius(d, dp, kind)
        g[2 * m] = d - p[o + M_B]
        g[2 * m + 1] = d + p[o + M_B]


@nb.njit(**_JIT)
def planetary_observe(t, y, out, p, s, c):
    """Dynamic mesh forces [N], one per mesh (sun-planet meshes, then ring-planet meshes)."""
    n, nm, nh, mesh, bs, st, mz = _offsets(p)
    if p[TWO_FLANK] == 0.0 and p[MULTI_ORDER] == 0.0:
        _mesh_forces_shared(y, out, p, n, nm, nh, mesh, bs, mz, s, c)
        return
    for m in range(nm):
        out[m] = _mesh_force(t, y, p, mesh + m * bs, mz + m * 3 * MESH_NZ, n, nh, s, c)


# ---------------------------------------------------------------------------------------------
# Lane-block forms (structure of arrays, lane k innermost): the arithmetic of the functions
# above, operation for operation, so a lane's result is bitwise the per-lane one's.


@nb.njit(inline="always", **_JIT)
def _lanes_offsets(PT):
    n = int(PT[N_DOF, 0])
    nm = int(PT[N_MESH, 0])
    nh = int(PT[N_HARM, 0])
    mesh = HEADER + 2 * n + 2 * n * n
    bs = block_size(n, nh)
    st = mesh + nm * bs
    mz = st + 1 + 3 * int(PT[st, 0])
    return n, nm, nh, mesh, bs, st, mz


@nb.njit(**_JIT_BODY)
def _lanes_stiffness(PT, nl, S, C, SC, rb, mesh, bs, nh, nm, first, top, uniform):
    """:func:`~geardyn.models.elements.harmonic_factor` of every mesh m into PT[rb + m] (the
    harmonic recurrence :func:`~geardyn.models.elements.harmonic_turn` in SC rows 0, 1), the same
    operations in the same order, clipped at 0 alike; ``first``: the offset of the coefficients in
    a mesh block (``MESH_FIXED``: the drive flank's). Each mesh's sum runs to the block's count
    over the multiples of the block's step (lane 0's ``harmonics`` and ``harmonic_step`` entries,
    :func:`_lanes_prepare_harmonics`; ``top``: the largest count, ``uniform``: every count ``top``
    and every step 1, the loop then checks neither); a stepped mesh's next harmonic in its
    ``harmonic_next`` entry of lane 0 (no division in the loop)."""
    if nh == 0:
        for m in range(nm):
            for k in range(nl):
                PT[rb + m, k] = 1.0
        return
    for m in range(nm):
        o = mesh + m * bs
        PT[o + M_HNEXT, 0] = PT[o + M_HSTEP, 0]
        f = o + first
        for k in range(nl):
            PT[rb + m, k] = PT[f, k] * C[k] + PT[f + 1, k] * S[k]
    for k in range(nl):
        SC[0, k] = C[k]
        SC[1, k] = S[k]
    for h in range(1, top):
        for k in range(nl):
            SC[0, k], SC[1, k] = harmonic_turn(SC[0, k], SC[1, k], C[k], S[k])
        for m in range(nm):
            if not uniform:
                o = mesh + m * bs
                if h >= PT[o + M_NH, 0]:
                    continue
                if PT[o + M_HSTEP, 0] != 1.0:  # a stepped series: its next harmonic only
                    if h + 1 != PT[o + M_HNEXT, 0]:
                        continue
                    PT[o + M_HNEXT, 0] += PT[o + M_HSTEP, 0]
            f = mesh + m * bs + first + 2 * h
            for k in range(nl):
                PT[rb + m, k] += PT[f, k] * SC[0, k] + PT[f + 1, k] * SC[1, k]
    for m in range(nm):
        for k in range(nl):
            PT[rb + m, k] = harmonic_clip(1.0 + PT[rb + m, k])


@nb.njit(inline="always", **_JIT)
def _lanes_prepare_harmonics(PT, nl, chk, mesh, bs, nh, nm):
    """The block's harmonic counts and steps: per mesh the most harmonics of its lanes
    (:func:`_lanes_harmonics`) and the greatest common divisor of their steps
    (:func:`_lanes_step`), kept in lane 0's ``harmonics`` and ``harmonic_step`` entries (a
    count at least lane 0's own, a step that divides its own: its sums are bitwise the same).
    Taken anew only after a slot was loaded (the row ``chk``, ``cache_harmonics_checked``, is
    then 0 in its column); the answer in that row of slot 0: 1 + the largest count, negative
    where some count is below it or some step above 1. Returns the largest count and whether
    every count is it and every step 1."""
    fresh = False
    for k in range(nl):
        fresh |= PT[chk, k] == 0.0
    if fresh:
        top = 0
        uniform = True
        for m in range(nm):
            o = mesh + m * bs
            hm = _lanes_harmonics(PT, nl, o, nh)
            hs = _lanes_step(PT, nl, o)
            PT[o + M_NH, 0] = hm
            PT[o + M_HSTEP, 0] = hs
            uniform &= hs == 1
            if m > 0 and hm != top:
                uniform = False
            top = max(top, hm)
        for k in range(nl):
            PT[chk, k] = 1.0
        PT[chk, 0] = (1.0 + top) if uniform else -(1.0 + top)
    v = PT[chk, 0]
    return int(abs(v)) - 1, v > 0.0


@nb.njit(inline="always", **_JIT)
def _lanes_cached_stiffness(PT, nl, S, C, SC, cache, mesh, bs, nh, nm, two):
    """Row of PT from which the relative stiffness of mesh m is row + m (its coast flank's row + nm,
    computed only with ``two``), at the forcing phase (S, C) of every lane. The block's PT carries a
    small cache (rows from ``cache``; reset to empty whenever a slot is loaded with a lane's
    coefficients): the four RK4 stages of a step see two new phases (the mid-step one twice, the end
    one again as the next step's start and for the observables), so half the evaluations are found
    there. An entry is used only where every lane's phase equals its key exactly, so the values are
    those computed anew (a slot loaded with a two-flank lane empties its keys, so an entry filled
    without the coast rows is not found by it)."""
    width = 2 + 2 * nm
    for e in range(CACHE_ENTRIES):
        b = cache + 1 + e * width
        hit = True
        for k in range(nl):
            hit &= (PT[b, k] == S[k]) & (PT[b + 1, k] == C[k])
        if hit:
            PT[cache, 0] = e
            return b + 2
    e = (int(PT[cache, 0]) + 1) % CACHE_ENTRIES  # not the entry used last
    b = cache + 1 + e * width
    top, uniform = _lanes_prepare_harmonics(PT, nl, cache + 1 + CACHE_ENTRIES * width + 1, mesh,
                                            bs, nh, nm)
    n = int(PT[N_DOF, 0])
    for flank in range(2 if two else 1):  # one call site: one compile, one copy
        first = MESH_FIXED if flank == 0 else coast_offset(n, nh)
        _lanes_stiffness(PT, nl, S, C, SC, b + 2 + flank * nm, mesh, bs, nh, nm, first, top,
                         uniform)
    for k in range(nl):
        PT[b, k] = S[k]
        PT[b + 1, k] = C[k]
    PT[cache, 0] = e
    return b + 2


@nb.njit(inline="always", **_JIT)
def _lanes_ct_uniform(PT, nl, cache, n):
    """Whether every lane of the block has the same Ct (e.g. a sweep in Omega), so that one
    copy serves all. Checked again only after a slot was loaded (its row ``CT_CHECKED`` of the
    cache section is then 0); the answer is kept in that row of slot 0."""
    chk = cache + 1 + CACHE_ENTRIES * (2 + 2 * int(PT[N_MESH, 0]))
    fresh = False
    for k in range(nl):
        fresh |= PT[chk, k] == 0.0
    if fresh:
        ct = HEADER + 2 * n + n * n
        same = True
        for r in range(ct, ct + n * n):
            v = PT[r, 0]
            for k in range(nl):
                same &= PT[r, k] == v
        for k in range(nl):
            PT[chk, k] = 1.0
        PT[chk, 0] = 2.0 if same else 1.0
    return PT[chk, 0] == 2.0


@nb.njit(inline="always", **_JIT)
def _lanes_ct_broadcast(Y, DY, PT, nl, n):
    """DY[n + i] -= sum_j Ct[i, j] Y[n + j] with slot 0's Ct for every lane (all equal), in the
    per-lane order: four terms per pass over the lanes, and four rows i at a time (each row's
    terms in the same order), so that every load of Y serves four rows."""
    ct = HEADER + 2 * n + n * n
    n4 = n - n % 4
    for i in range(0, n4, 4):
        r = ct + i * n
        for j in range(0, n4, 4):
            a0 = PT[r + j, 0]
            a1 = PT[r + j + 1, 0]
            a2 = PT[r + j + 2, 0]
            a3 = PT[r + j + 3, 0]
            b0 = PT[r + n + j, 0]
            b1 = PT[r + n + j + 1, 0]
            b2 = PT[r + n + j + 2, 0]
            b3 = PT[r + n + j + 3, 0]
            c0 = PT[r + 2 * n + j, 0]
            c1 = PT[r + 2 * n + j + 1, 0]
            c2 = PT[r + 2 * n + j + 2, 0]
            c3 = PT[r + 2 * n + j + 3, 0]
            d0 = PT[r + 3 * n + j, 0]
            d1 = PT[r + 3 * n + j + 1, 0]
            d2 = PT[r + 3 * n + j + 2, 0]
            d3 = PT[r + 3 * n + j + 3, 0]
            for k in range(nl):
                y0 = Y[n + j, k]
                y1 = Y[n + j + 1, k]
                y2 = Y[n + j + 2, k]
                y3 = Y[n + j + 3, k]
                DY[n + i, k] = DY[n + i, k] - a0 * y0 - a1 * y1 - a2 * y2 - a3 * y3
                DY[n + i + 1, k] = DY[n + i + 1, k] - b0 * y0 - b1 * y1 - b2 * y2 - b3 * y3
                DY[n + i + 2, k] = DY[n + i + 2, k] - c0 * y0 - c1 * y1 - c2 * y2 - c3 * y3
                DY[n + i + 3, k] = DY[n + i + 3, k] - d0 * y0 - d1 * y1 - d2 * y2 - d3 * y3
        for j in range(n4, n):
            for q in range(4):
                c = PT[r + q * n + j, 0]
                for k in range(nl):
                    DY[n + i + q, k] -= c * Y[n + j, k]
    for i in range(n4, n):
        r = ct + i * n
        for j in range(0, n4, 4):
            c0 = PT[r + j, 0]
            c1 = PT[r + j + 1, 0]
            c2 = PT[r + j + 2, 0]
            c3 = PT[r + j + 3, 0]
            for k in range(nl):
                DY[n + i, k] = (DY[n + i, k] - c0 * Y[n + j, k] - c1 * Y[n + j + 1, k]
                                - c2 * Y[n + j + 2, k] - c3 * Y[n + j + 3, k])
        for j in range(n4, n):
            c0 = PT[r + j, 0]
            for k in range(nl):
                DY[n + i, k] -= c0 * Y[n + j, k]


@nb.njit(**_JIT_LANES)
def planetary_rhs_lanes(T, Y, DY, PT, nl, S, C, SC):
    """:func:`planetary_rhs` for lanes 0..nl-1 of a block."""
    n, nm, nh, mesh, bs, st, mz = _lanes_offsets(PT)
    torque = False
    damped = False
    for k in range(nl):
        torque |= PT[TORQUE_ON, k] != 0.0
        damped |= PT[DAMPED, k] != 0.0
    for k in range(nl):
        SC[0, k] = 0.0
    if torque:
        for k in range(nl):
            if PT[TORQUE_ON, k] != 0.0:
                SC[0, k] = _torque_wave(T[k], PT[TORQUE_ORDER, k], PT[OMEGA, k],
                                        PT[TORQUE_PHASE, k], S[k], C[k])
    f1 = HEADER + n
    for i in range(n):
        for k in range(nl):
            DY[i, k] = Y[n + i, k]
            DY[n + i, k] = PT[HEADER + i, k] + PT[f1 + i, k] * SC[0, k]
    nk = int(PT[st, 0])
    for e in range(nk):
        i = n + int(PT[st + 1 + e, 0])
        j = int(PT[st + 1 + nk + e, 0])
        r = st + 1 + 2 * nk + e
        for k in range(nl):
            DY[i, k] -= PT[r, k] * Y[j, k]
    if damped and _lanes_ct_uniform(PT, nl, mz + nm * 3 * MESH_NZ, n):
        _lanes_ct_broadcast(Y, DY, PT, nl, n)
    elif damped:  # Ct = 0 in an undamped lane: its terms subtract zeros
        ct = HEADER + 2 * n + n * n
        n4 = n - n % 4
        for i in range(n):
            r = ct + i * n
            for j in range(0, n4, 4):  # four terms per pass over the lanes, in order
                for k in range(nl):
                    DY[n + i, k] = (DY[n + i, k] - PT[r + j, k] * Y[n + j, k]
                                    - PT[r + j + 1, k] * Y[n + j + 1, k]
                                    - PT[r + j + 2, k] * Y[n + j + 2, k]
                                    - PT[r + j + 3, k] * Y[n + j + 3, k])
            for j in range(n4, n):
                for k in range(nl):
                    DY[n + i, k] -= PT[r + j, k] * Y[n + j, k]
    g = _gyro_offset(nm, mz)
    spinning = False
    for k in range(nl):
        spinning |= PT[g, k] != 0.0
    if spinning:  # w_c = 0 in a lane: its terms subtract zeros (as the scalar form skips them)
        ng = int(PT[g + 1, 0])
        for e in range(ng):
            i = n + int(PT[g + 2 + e, 0])
            j = n + int(PT[g + 2 + ng + e, 0])
            r = g + 2 + 2 * ng + e
            for k in range(nl):
                DY[i, k] -= (PT[g, k] * PT[r, k]) * Y[j, k]
    _lanes_meshes(T, Y, DY, PT, nl, S, C, SC, bool(nl >= 0))


@nb.njit(**_JIT_INL)
def _lanes_meshes(T, Y, DY, PT, nl, S, C, SC, apply):
    """The mesh forces of lanes 0..nl-1 of a block, each subtracted from the accelerations DY
    through its mesh's G (``apply``: :func:`planetary_rhs_lanes`) or written to row m of DY
    (:func:`planetary_observe_lanes`); the relative stiffnesses from the block's caches
    (:func:`_lanes_cached_stiffness`, :func:`_lanes_own_phases`). Inlined by LLVM (``_JIT_INL``):
    called, the right-hand side's mesh loop ran 1.13-1.26x slower. The callers pass ``apply``
    as a value computed at run time (``bool(nl >= 0)``, ``bool(nl < 0)``: True and False, and
    either does nothing for nl = 0), not a constant, which numba would type as a literal and
    compile this function for each."""
    n, nm, nh, mesh, bs, st, mz = _lanes_offsets(PT)
    two = False
    for k in range(nl):
        two |= PT[TWO_FLANK, k] != 0.0
    multi = _lanes_multi_order(PT, nl)
    kr = _lanes_cached_stiffness(PT, nl, S, C, SC, mz + nm * 3 * MESH_NZ, mesh, bs, nh, nm, two)
    ko = _lanes_own_phases(T, PT, nl, S, C, _own_offset(PT, nm, mz), n, nh, nm, mesh, bs,
                           _gyro_offset(nm, mz) - 1) \
        if multi else 0
    for m in range(nm):
        if multi and not _lanes_order_one(PT, nl, mesh + m * bs):
            _lanes_mesh_own(Y, DY, PT, nl, SC, n, nm, mesh + m * bs, mz + m * 3 * MESH_NZ,
                            ko + m, apply, m)
        else:
            _lanes_mesh(Y, DY, PT, nl, S, C, SC, n, mesh + m * bs, mz + m * 3 * MESH_NZ,
                        kr + m, apply, two, kr + nm + m, m)


@nb.njit(inline="always", **_JIT)
def _mesh_dofs(PT, q):
    """The six dof indices of the mesh whose structure starts at row q (column 0)."""
    return (int(PT[q, 0]), int(PT[q + 1, 0]), int(PT[q + 2, 0]), int(PT[q + 3, 0]),
            int(PT[q + 4, 0]), int(PT[q + 5, 0]))


@nb.njit(inline="always", **_JIT)
def _lane_deflection(Y, PT, k, n, o, w, i0, i1, i2, i3, i4, i5, s, c, om):
    """Lane k's mesh deflection d less the mesh error, and its rate v (block at o, projection
    weights at row w, dofs i0..i5; s, c: the lane's mesh phase, turning at om), in the order
    every form sums them."""
    d = 0.0
    v = 0.0
    d += PT[w, k] * Y[i0, k]
    v += PT[w, k] * Y[n + i0, k]
    d += PT[w + 1, k] * Y[i1, k]
    v += PT[w + 1, k] * Y[n + i1, k]
    d += PT[w + 2, k] * Y[i2, k]
    v += PT[w + 2, k] * Y[n + i2, k]
    d += PT[w + 3, k] * Y[i3, k]
    v += PT[w + 3, k] * Y[n + i3, k]
    d += PT[w + 4, k] * Y[i4, k]
    v += PT[w + 4, k] * Y[n + i4, k]
    d += PT[w + 5, k] * Y[i5, k]
    v += PT[w + 5, k] * Y[n + i5, k]
    d -= PT[o + M_ES, k] * s + PT[o + M_EC, k] * c
    v -= om * (PT[o + M_ES, k] * c - PT[o + M_EC, k] * s)
    return d, v


@nb.njit(inline="always", **_JIT)
def _other_row(PT, n, o, q):
    """The other row of the radial contact whose block is at o (structure at q): its block's
    offset, its weights' row and its six dofs, from column 0 (structure: the same in every
    lane), so that the lane loops index it as they index the contact's own row."""
    j = int(PT[o + M_RADIAL, 0])
    qp = q + j * 3 * MESH_NZ
    i0, i1, i2, i3, i4, i5 = _mesh_dofs(PT, qp)
    return o + j * block_size(n, int(PT[N_HARM, 0])), qp + MESH_NZ, i0, i1, i2, i3, i4, i5


@nb.njit(inline="always", **_JIT)
def _lanes_mesh(Y, DY, PT, nl, S, C, SC, n, o, q, row, apply, two, rowc, m):
    """Mesh force of the block at o (structure at q, relative stiffness in PT[row]) for every
    lane, into SC[0], then subtracted from the accelerations DY (``apply``) or copied to DY[m]
    (observables). One store stream per lane loop, so that the loops vectorise. With ``two``
    the coast flank's KF_coast c_m(theta) (relative stiffness in PT[rowc]) acts where the dead
    zone's output is negative; the drive flank's arithmetic is the same either way. A radial
    contact's g takes its other row's deflection (:func:`_other_row`), as :func:`_zone`."""
    i0, i1, i2, i3, i4, i5 = _mesh_dofs(PT, q)
    w = q + MESH_NZ
    kind = PT[o + M_RADIAL, 0]
    if kind != 0.0:
        op, wp, j0, j1, j2, j3, j4, j5 = _other_row(PT, n, o, q)
        for k in range(nl):
            d, v = _lane_deflection(Y, PT, k, n, o, w, i0, i1, i2, i3, i4, i5, S[k], C[k],
                                    PT[OMEGA, k])
            dp, _ = _lane_deflection(Y, PT, k, n, op, wp, j0, j1, j2, j3, j4, j5, S[k], C[k],
                                     PT[OMEGA, k])
            g = radial_zone(d, _radius(d, dp, kind), PT[o + M_B, k])
            kf = PT[o + M_KF, k] * PT[row, k]
            if two and g < 0.0:
                kf = PT[o + M_KFC, k] * PT[rowc, k]
            SC[0, k] = kf * g + PT[o + M_CF, k] * v
        _lanes_apply(DY, PT, nl, SC, n, q, apply, m)
        return
    for k in range(nl):
        d, v = _lane_deflection(Y, PT, k, n, o, w, i0, i1, i2, i3, i4, i5, S[k], C[k],
                                PT[OMEGA, k])
        g = dead_zone(d, PT[o + M_B, k])
        kf = PT[o + M_KF, k] * PT[row, k]
        if two and g < 0.0:
            kf = PT[o + M_KFC, k] * PT[rowc, k]
        SC[0, k] = kf * g + PT[o + M_CF, k] * v
    _lanes_apply(DY, PT, nl, SC, n, q, apply, m)


@nb.njit(inline="always", **_JIT)
def _lanes_apply(DY, PT, nl, SC, n, q, apply, m):
    """The mesh force in SC[0] subtracted from the accelerations DY through the mesh's G
    (structure at q; ``apply``) or copied to DY[m] (observables)."""
    if not apply:
        for k in range(nl):
            DY[m, k] = SC[0, k]
        return
    g = q + 2 * MESH_NZ
    for j in range(MESH_NZ):
        r = n + int(PT[q + j, 0])
        for k in range(nl):
            DY[r, k] -= SC[0, k] * PT[g + j, k]


@nb.njit(**_JIT_LANES)
def planetary_events_lanes(T, Y, G, PT, nl, S, C):
    """:func:`planetary_events` for lanes 0..nl-1 of a block (the mesh phase S[k], C[k])."""
    n, nm, nh, mesh, bs, st, mz = _lanes_offsets(PT)
    multi = _lanes_multi_order(PT, nl)
    ko = _lanes_own_phases(T, PT, nl, S, C, _own_offset(PT, nm, mz), n, nh, nm, mesh, bs,
                           _gyro_offset(nm, mz) - 1) \
        if multi else 0
    for m in range(nm):
        o = mesh + m * bs
        q = mz + m * 3 * MESH_NZ
        if multi and not _lanes_order_one(PT, nl, o):
            _events_lanes_own(Y, G, PT, nl, n, nm, m, o, q, ko + m)
            continue
        if PT[o + M_RADIAL, 0] != 0.0:
            _events_lanes_radial(Y, G, PT, nl, n, m, o, q, S, C)
            continue
        w = q + MESH_NZ
        i0 = int(PT[q, 0])
        i1 = int(PT[q + 1, 0])
        i2 = int(PT[q + 2, 0])
        i3 = int(PT[q + 3, 0])
        i4 = int(PT[q + 4, 0])
        i5 = int(PT[q + 5, 0])
        for k in range(nl):  # the deflection into row 2m + 1 first: one store per loop
            d = 0.0
            d += PT[w, k] * Y[i0, k]
            d += PT[w + 1, k] * Y[i1, k]
            d += PT[w + 2, k] * Y[i2, k]
            d += PT[w + 3, k] * Y[i3, k]
            d += PT[w + 4, k] * Y[i4, k]
            d += PT[w + 5, k] * Y[i5, k]
            G[2 * m + 1, k] = d - (PT[o + M_ES, k] * S[k] + PT[o + M_EC, k] * C[k])
        for k in range(nl):
            d = G[2 * m + 1, k]
            G[2 * m, k] = d - PT[o + M_B, k]
            G[2 * m + 1, k] = d + PT[o + M_B, k]


@nb.njit(**_JIT_LANES)
def planetary_observe_lanes(T, Y, O, PT, nl, S, C, SC):
    """:func:`planetary_observe` for lanes 0..nl-1 of a block (O: one row per mesh)."""
    _lanes_meshes(T, Y, O, PT, nl, S, C, SC, bool(nl < 0))


# ---------------------------------------------------------------------------------------------
# Lane-block forms of a mesh whose order differs from 1 in a lane (a gear train's other stages):
# the mesh at its own phase (:func:`_mesh_phase`) per lane, from the own-phase cache
# (:func:`_lanes_own_phases`); a mesh of order 1 in every lane keeps the shared-phase forms.


@nb.njit(inline="always", **_JIT)
def _lanes_multi_order(PT, nl):
    """Whether a lane of the block has a mesh whose order differs from 1."""
    multi = False
    for k in range(nl):
        multi |= PT[MULTI_ORDER, k] != 0.0
    return multi


@nb.njit(inline="always", **_JIT)
def _lanes_order_one(PT, nl, o):
    """Whether the mesh whose block is at o has order 1 in every lane of the block, or is a
    radial contact (no error, relative stiffness 1: its phase is unused, and its values are
    those at any phase), so that the shared-phase forms serve it."""
    if PT[o + M_RADIAL, 0] != 0.0:
        return True
    one = True
    for k in range(nl):
        one &= PT[o + M_ORDER, k] == 1.0
    return one


@nb.njit(inline="always", **_JIT)
def _own_phases_lane(PT, k, t, s, c, r, nm, mesh, bs):
    """Sin and cos of every mesh's own phase (:func:`_mesh_phase`) in lane k at the time t and
    the forcing phase s, c into rows r + m and r + nm + m; a mesh whose order equals the
    previous mesh's in the lane (a stage's meshes) takes that mesh's values (the same)."""
    om = PT[OMEGA, k]
    last = 1.0
    sm = s
    cm = c
    for m in range(nm):
        order = PT[mesh + m * bs + M_ORDER, k]
        if order == 1.0:
            PT[r + m, k] = s
            PT[r + nm + m, k] = c
            continue
        if order != last:
            sm, cm, _ = _mesh_phase(t, order, om, s, c)
            last = order
        PT[r + m, k] = sm
        PT[r + nm + m, k] = cm


@nb.njit(**_JIT_BODY)
def _lanes_own_stiffness(PT, nl, rs, rc, out, f, nh, step, x):
    """:func:`~geardyn.models.elements.harmonic_factor_lane` of the coefficients at row f for every
    lane at the phase whose sin and cos are in rows rs and rc, into row out (the harmonic
    recurrence :func:`~geardyn.models.elements.harmonic_turn` in rows x, x + 1): the same
    operations in the same order, clipped at 0 alike; past the first harmonic only the multiples of
    ``step`` added (:func:`_stepped_factor`)."""
    if nh == 0:
        for k in range(nl):
            PT[out, k] = 1.0
        return
    nxt = step if step > 1 else 2  # the next harmonic to add
    for k in range(nl):
        PT[out, k] = PT[f, k] * PT[rc, k] + PT[f + 1, k] * PT[rs, k]
        PT[x, k] = PT[rc, k]
        PT[x + 1, k] = PT[rs, k]
    for h in range(1, nh):
        for k in range(nl):
            PT[x, k], PT[x + 1, k] = harmonic_turn(PT[x, k], PT[x + 1, k], PT[rc, k], PT[rs, k])
        if h + 1 != nxt:
            continue
        nxt += step
        for k in range(nl):
            PT[out, k] += PT[f + 2 * h, k] * PT[x, k] + PT[f + 2 * h + 1, k] * PT[x + 1, k]
    for k in range(nl):
        PT[out, k] = harmonic_clip(1.0 + PT[out, k])


@nb.njit(inline="always", **_JIT)
def _own_key(PT, b, k, t, s, c):
    """Whether lane k's cache entry at row b has the key (t, s, c)."""
    return (PT[b, k] == t) & (PT[b + 1, k] == s) & (PT[b + 2, k] == c)


@nb.njit(**_JIT_BODY)
def _lanes_own_phases(T, PT, nl, S, C, own, n, nh, nm, mesh, bs, chk):
    """Row r of the own-phase cache entry at the lanes' times T and forcing phases (S, C): row
    r + m holds the sin of mesh m's own phase, r + nm + m its cos, r + 2 nm + m its drive
    relative stiffness there, r + 3 nm + m its coast one (computed where a lane of the block
    has two flanks, and only for the meshes that take the own-phase forms: not
    :func:`_lanes_order_one`; each to the block's harmonic count over its step,
    :func:`_lanes_prepare_harmonics`, whose checked row is ``chk``). The block's PT carries
    ``OWN_ENTRIES`` (2) entries after two scratch rows from row ``own`` + 1 (all zero, empty,
    whenever a slot is loaded with a lane's coefficients): the four RK4 stages of a step see
    two new times (the mid-step one twice, the end one again for the events, the observables
    and as the next step's start), so the sin and cos of each distinct mesh order are computed
    twice a step per lane, not five times per mesh. A lane's phases are reused only where its
    key (time and forcing phase) equals the call's exactly, so the values are those computed
    anew."""
    width = 3 + 4 * nm
    x = own + 1  # scratch of the harmonic recurrence
    for e in range(OWN_ENTRIES):
        b = own + 3 + e * width
        hit = True
        for k in range(nl):
            hit &= _own_key(PT, b, k, T[k], S[k], C[k])
        if hit:
            PT[own, 0] = e
            return b + 3
    e = (int(PT[own, 0]) + 1) % OWN_ENTRIES  # not the entry used last
    b = own + 3 + e * width
    a = own + 3 + ((e + 1) % OWN_ENTRIES) * width  # the other one
    r = b + 3
    for k in range(nl):
        if _own_key(PT, b, k, T[k], S[k], C[k]):
            continue
        if _own_key(PT, a, k, T[k], S[k], C[k]):
            for j in range(3, 3 + 2 * nm):
                PT[b + j, k] = PT[a + j, k]
        else:
            _own_phases_lane(PT, k, T[k], S[k], C[k], r, nm, mesh, bs)
        PT[b, k] = T[k]
        PT[b + 1, k] = S[k]
        PT[b + 2, k] = C[k]
    two = False
    for k in range(nl):
        two |= PT[TWO_FLANK, k] != 0.0
    _lanes_prepare_harmonics(PT, nl, chk, mesh, bs, nh, nm)
    for m in range(nm):
        o = mesh + m * bs
        if _lanes_order_one(PT, nl, o):  # the shared-phase forms': these rows are not read
            continue
        hm = int(PT[o + M_NH, 0])
        hs = int(PT[o + M_HSTEP, 0])
        for flank in range(2 if two else 1):  # one call site: one compile, one copy
            first = MESH_FIXED if flank == 0 else coast_offset(n, nh)
            _lanes_own_stiffness(PT, nl, r + m, r + nm + m, r + (2 + flank) * nm + m, o + first,
                                 hm, hs, x)
    PT[own, 0] = e
    return r


@nb.njit(inline="always", **_JIT)
def _lanes_mesh_own(Y, DY, PT, nl, SC, n, nm, o, q, r, apply, m):
    """:func:`_lanes_mesh` with the mesh at its own phase in every lane (:func:`_mesh_phase`),
    its sin, cos and relative stiffnesses at rows r, r + nm, r + 2 nm, r + 3 nm of the
    own-phase cache (:func:`_lanes_own_phases`); the coast flank's where the lane has two
    flanks and the dead zone's output is negative."""
    i0, i1, i2, i3, i4, i5 = _mesh_dofs(PT, q)
    w = q + MESH_NZ
    for k in range(nl):
        order = PT[o + M_ORDER, k]
        om = PT[OMEGA, k] if order == 1.0 else order * PT[OMEGA, k]
        d, v = _lane_deflection(Y, PT, k, n, o, w, i0, i1, i2, i3, i4, i5, PT[r, k],
                                PT[r + nm, k], om)
        g = dead_zone(d, PT[o + M_B, k])
        kd = PT[o + M_KF, k] * PT[r + 2 * nm, k]
        kc = PT[o + M_KFC, k] * PT[r + 3 * nm, k]
        kf = kc if (PT[TWO_FLANK, k] != 0.0) & (g < 0.0) else kd
        SC[0, k] = kf * g + PT[o + M_CF, k] * v
    _lanes_apply(DY, PT, nl, SC, n, q, apply, m)


@nb.njit(inline="always", **_JIT)
def _events_lanes_own(Y, G, PT, nl, n, nm, m, o, q, r):
    """:func:`planetary_events_lanes`' rows of mesh m (block at o, structure at q) at the
    mesh's own phase (sin and cos at rows r, r + nm of the own-phase cache)."""
    i0, i1, i2, i3, i4, i5 = _mesh_dofs(PT, q)
    w = q + MESH_NZ
    for k in range(nl):
        d, _ = _lane_deflection(Y, PT, k, n, o, w, i0, i1, i2, i3, i4, i5, PT[r, k],
                                PT[r + nm, k], 0.0)
        G[2 * m, k] = d - PT[o + M_B, k]
        G[2 * m + 1, k] = d + PT[o + M_B, k]


@nb.njit(inline="always", **_JIT)
def _events_lanes_radial(Y, G, PT, nl, n, m, o, q, S, C):
    """:func:`planetary_events_lanes`' rows of the radial contact m (block at o, structure at
    q): r - b and r + b, r the radius of its two rows' deflections (:func:`_radius`)."""
    i0, i1, i2, i3, i4, i5 = _mesh_dofs(PT, q)
    w = q + MESH_NZ
    kind = PT[o + M_RADIAL, 0]
    op, wp, j0, j1, j2, j3, j4, j5 = _other_row(PT, n, o, q)
    for k in range(nl):
        d, _ = _lane_deflection(Y, PT, k, n, o, w, i0, i1, i2, i3, i4, i5, S[k], C[k],
                                PT[OMEGA, k])
        dp, _ = _lane_deflection(Y, PT, k, n, op, wp, j0, j1, j2, j3, j4, j5, S[k], C[k],
                                 PT[OMEGA, k])
        r = _radius(d, dp, kind)
        G[2 * m, k] = r - PT[o + M_B, k]
        G[2 * m + 1, k] = r + PT[o + M_B, k]
