"""Linear solvers of the one linear system per step, with their state explicit.

Every step of every method solves ``A p = b``, ``A = D + G C`` (:class:`StepOperator`:
``D`` sparse, ``G`` the sparse sum of the terms' film operators, ``C`` the substrate's
compliance).  The solvers are registered in :data:`LINEAR_SOLVERS`: ``"lu"`` (a direct LU
every step) and ``"gmres"`` (recycled GCR preconditioned by a refreshed LU; with the fast
operator the near field's sparse LU after the coarse correction :class:`TwoLevel`).  All
state lives on the solver instance; a solver serves one stepper.  The solvers, their
refresh rules and tolerances: docs/design.md section 3.2 (and sections 9-10).
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from femehl.elastic.dense import is_dense
from femehl.errors import SceneError, SingularSystemError
from femehl.registry import Registry
from femehl.validation import check_in_range

__all__ = [
    "StepOperator",
    "SwitchedOperator",
    "BorderedOperator",
    "LINEAR_SOLVERS",
    "register_linear_solver",
    "DirectSolver",
    "RecycledGCR",
    "TwoLevel",
    "make_linear_solver",
    "film_rtol_scale",
    "film_tolerances",
]


@dataclass
class StepOperator:
    """``A = D + sum_i c_i F_i C`` of one step.

    Attributes
    ----------
    D : sparse matrix (n, n)
        The part acting on the unknowns directly.
    films : list of (coefficient, F, FC)
        Film operators ``F`` (sparse, n x film points) with their fixed products ``F C``
        (for a fast ``C``: the sparse near-field product, used by the preconditioner only).
    C : ndarray or sparse matrix (film points, n)
        Compliance: ``d = h + C p`` on the film points.
    key : float
        A number that changes when the matrix changes a lot (``a0/dt``): LU refresh.
    held : ndarray of int or None
        The rows :meth:`with_fixed` replaced (the cavitated nodes), None if none.
    """

    D: sp.spmatrix
    films: list
    C: object
    key: float
    held: np.ndarray | None = None

    @property
    def dense(self) -> bool:
        return is_dense(self.C)

    @property
    def fast(self) -> bool:
        """``C`` is a hierarchical operator: products only, ``matrix()`` does not exist."""
        return bool(getattr(self.C, "is_fast", False))

    def near_matrix(self):
        """Sparse CSC ``D + sum_i c_i F_i C_near`` of a fast operator: the preconditioner."""
        return self._sparse_sum()

    def coarse_system(self):
        """``(P, A P)`` on the coarse space of a fast ``C`` (``C.coarse = (P, C P)``), or
        None without one.  ``A P = D P + G (C P)``: sparse work, single precision (it
        serves the preconditioner, :class:`TwoLevel`)."""
        coarse = getattr(self.C, "coarse", None)
        if coarse is None:
            return None
        P, CP = coarse
        AP = np.asarray(self.G.astype(np.float32) @ CP)  # no double copy of C P
        DP = (self.D @ P).tocoo()
        np.add.at(AP, (DP.row, DP.col), DP.data.astype(np.float32))
        return P, AP

    def _sparse_sum(self):
        """``D + sum_i c_i (F C)_i`` with the stored sparse products, as CSC."""
        A = self.D
        for c, _, FC in self.films:
            A = A + c * FC
        return sp.csc_matrix(A)

    @cached_property
    def G(self):
        """``sum_i c_i F_i`` (sparse, n x film points), formed once per step."""
        G = None
        for c, F, _ in self.films:
            G = F * c if G is None else G + F * c
        if G is None:
            G = sp.csr_matrix((self.D.shape[0], self.C.shape[0]))
        return G.tocsr()

    def matrix(self, dtype=np.float64):
        """The whole ``A``: dense, formed in place (row blocks, C-ordered), or sparse CSC."""
        if self.fast:
            raise SceneError(
                "the fast elastic operator is never formed, so this system has no matrix for a "
                "direct solve: use linear_solver='gmres' (the default) or operator='dense'."
            )
        if not self.dense:
            return self._sparse_sum()
        n = self.D.shape[0]
        if not self.films:
            A = np.zeros((n, n), dtype=dtype)
        else:
            A = np.empty((n, n), dtype=dtype)
            # row blocks of ~128k entries (1 MB in float64), summed in one scratch block with
            # no temporaries: one pass over each F C (0.26 -> 0.21 s at 5,765 unknowns); a
            # step's product is added into the block's rows (``StepProduct``), so every sum
            # is in double and rounded to ``dtype`` once (in deep contact the rough film's
            # product nearly cancels the terms')
            blk = max(1, (1 << 17) // max(n, 1))
            acc, tmp = np.empty((min(blk, n), n)), np.empty((min(blk, n), n))
            for s in range(0, n, blk):
                a, b = acc[: min(blk, n - s)], tmp[: min(blk, n - s)]
                for k, (c, _, FC) in enumerate(self.films):
                    if isinstance(FC, StepProduct):
                        if k == 0:
                            a[:] = 0.0
                        FC.add_into(a, c, s)
                        continue
                    np.multiply(FC[s : s + blk], c, out=b if k else a)
                    if k:
                        a += b
                A[s : s + blk] = a
        Dc = self.D.tocoo()
        np.add.at(A, (Dc.row, Dc.col), Dc.data.astype(dtype))
        return A

    def apply(self, Z, CZ, G=None):
        """``A Z`` for columns ``Z`` whose ``C Z`` is known: sparse work only."""
        G = self.G if G is None else G
        return self.D @ Z + G @ CZ

    def columns(self, idx, dtype=np.float64) -> np.ndarray:
        """The dense columns ``A[:, idx]`` (n x len(idx)) of a dense operator."""
        out = self.D[:, idx].toarray().astype(dtype)
        for c, _, FC in self.films:
            out += c * FC[:, idx]
        return out

    def factorize(self, dtype, t):
        """An LU of the dense ``A`` with ``.solve(b)`` (``A x = b``), in ``dtype``."""
        return DenseLU(self.matrix(dtype=dtype), t)

    def with_fixed(self, fixed) -> StepOperator:
        """The operator with the rows ``fixed`` replaced by identity rows (``x_i = b_i``).

        ``A' = R A + E`` with ``R`` the identity without the fixed rows and ``E`` their
        unit diagonal: ``D' = R D + E``, ``F' = R F`` and ``(F C)' = R (F C)`` (a dense
        product is masked row by row when it is read, never copied).  Used for pressures
        held at 0 (cavitated nodes).
        """
        fixed = np.asarray(fixed, dtype=np.int64)
        if fixed.size == 0:
            return self
        n = self.D.shape[0]
        keep = np.ones(n)
        keep[fixed] = 0.0
        R = sp.diags(keep)
        E = sp.csr_matrix((np.ones(fixed.size), (fixed, fixed)), shape=(n, n))
        films = [(c, (R @ F).tocsr(), _rows_of(FC, R, keep)) for c, F, FC in self.films]
        return StepOperator(D=(R @ self.D + E).tocsr(), films=films, C=self.C, key=self.key, held=fixed)

    def with_film(self, c, F, FC) -> StepOperator:
        """The operator with one more film operator ``c F`` (and its product ``F C``)."""
        return dataclasses.replace(self, films=[*self.films, (c, F, FC)])


class StepProduct:
    """``F C`` of a film operator ``F`` of one step only (a rough film's,
    :mod:`femehl.problem.roughness`) and a dense ``C``, never formed whole.

    A Krylov step applies ``A z = D z + G (C z)`` and reads ``F C`` only when it forms or
    refreshes its preconditioner: :meth:`StepOperator.matrix` adds ``c F C`` into its row
    blocks in double (:meth:`add_into`, one row of ``C`` per nonzero of ``F``), and
    :meth:`StepOperator.columns` reads a few columns.  Formed whole, it took a float64
    copy of ``C``'s rows and an n x n array at every refresh (the rough PDMS ball, fitted
    level 1.15, 8,222 elements: 0.94 s a refresh, 0.75 s added into the row blocks).
    """

    def __init__(self, F, C):
        self.F = sp.csr_matrix(F)
        self.C = C
        self.shape = (self.F.shape[0], C.shape[1])

    def add_into(self, out, c: float, start: int = 0) -> None:
        """``out += c (F C)[start : start + len(out)]`` (``out`` dense rows of ``A``)."""
        W = self.F[start : start + out.shape[0]] * c
        if W.nnz == 0:
            return
        if hasattr(self.C, "add_product"):  # a single-precision dense C: no copy of it
            self.C.add_product(W, out)
            return
        rows = np.flatnonzero(np.diff(W.indptr))
        out[rows] += np.asarray(W[rows] @ self.C)

    def __getitem__(self, key):
        """``(F C)[rows, cols]``: a few columns (:meth:`StepOperator.columns`)."""
        rows, cols = key
        return np.asarray(self.F[rows] @ self.C[:, cols])

    def with_rows(self, R) -> StepProduct:
        """``(R F) C``: the rows ``R`` keeps (:meth:`StepOperator.with_fixed`)."""
        return StepProduct(R @ self.F, self.C)


def _rows_of(FC, R, keep):
    """``R FC``: a product with the rows ``R`` keeps (``keep`` their 0/1 mask)."""
    if sp.issparse(FC):
        return (R @ FC).tocsr()
    if isinstance(FC, StepProduct):
        return FC.with_rows(R)
    return _RowMasked(FC, keep)


class _RowMasked:
    """A dense ``F C`` read with some rows zeroed (``matrix()`` reads row blocks)."""

    def __init__(self, FC, keep):
        self.FC, self.keep = FC, keep
        self.shape = FC.shape

    def __getitem__(self, key):
        rows, cols = key if isinstance(key, tuple) else (key, slice(None))
        return self.FC[rows, cols] * self.keep[rows, None]


class SwitchedOperator:
    """A step whose unknown ``j`` is ``p_j``, or on the switched set ``S`` an auxiliary ``v_j``.

    The system of ``2n`` unknowns ``(p, v)`` (a mass-conserving cavitation step,
    :class:`femehl.problem.cavitation.JFOCavitation`: ``v`` the gas film)::

        [ A      -B P_S ] [p]   [b]
        [ E_S     E_F   ] [v] = [0]      (p_j = 0 on S, v_j = 0 off it)

    with ``A`` the :class:`StepOperator` ``base`` and ``B`` sparse.  Only ``A`` holds the
    dense (or hierarchical) compliance, and it acts on ``p`` alone: ``C`` of this operator
    is ``base.C`` reading the first ``n`` entries, so the recycled ``(z, C z)`` of the
    Krylov solver stay valid whatever ``S`` was when they were made.  Its direct solve
    is one LU of the ``n x n`` matrix ``M = A P_F - B P_S`` (the columns of ``S`` replaced
    by those of ``-B``), :class:`SwitchedLU`; a sparse ``C`` (Winkler, rigid) gives a
    sparse ``2n x 2n`` matrix, the fast operator a sparse ``near_matrix``.
    """

    def __init__(self, base: StepOperator, B, switched):
        self.base = base
        self.B = sp.csr_matrix(B)
        self.switched = np.asarray(switched, dtype=bool)
        self.n = n = base.D.shape[0]
        self.key = base.key
        self.C = _Leading(base.C, n)
        on = self.switched.astype(float)
        self._blocks = (-self.B @ sp.diags(on), sp.diags(on), sp.diags(1.0 - on))

    @property
    def dense(self) -> bool:
        return self.base.dense

    @property
    def fast(self) -> bool:
        return self.base.fast

    def _stack(self, A):
        mBS, ES, EF = self._blocks
        return sp.bmat([[A, mBS], [ES, EF]], format="csr")

    @cached_property
    def D(self):
        return self._stack(self.base.D)

    @cached_property
    def G(self):
        G = self.base.G
        return sp.vstack([G, sp.csr_matrix((self.n, G.shape[1]))], format="csr")

    apply = StepOperator.apply  # D Z + G C Z, with this operator's D and G

    def near_matrix(self):
        return sp.csc_matrix(self._stack(self.base.near_matrix()))

    def coarse_system(self):
        """None: the coarse space is one of pressures, and the switched unknowns are not
        all pressures (its preconditioner is the near-field LU alone)."""
        return None

    def matrix(self, dtype=np.float64):
        """The sparse ``2n x 2n`` matrix (a sparse ``C``); a dense one is never formed."""
        if self.dense or self.fast:
            raise SceneError("a switched dense step is solved through factorize(), not matrix().")
        return sp.csc_matrix(self._stack(self.base.matrix()))

    def factorize(self, dtype, t):
        return SwitchedLU(self, dtype, t)


class _Leading:
    """``C`` acting on the first ``n`` entries of a ``2n`` vector (or of its columns)."""

    def __init__(self, C, n):
        self.C, self.n = C, n
        self.shape = (C.shape[0], 2 * n)

    def __matmul__(self, z):
        return self.C @ z[: self.n]


class DenseLU:
    """LAPACK LU of a dense, C-ordered ``A`` (factored as ``A^T``, no copy): ``solve(b)``."""

    def __init__(self, A, t):
        self.lu = _dense_lu(A, t)
        self.dtype = A.dtype

    def solve(self, b):
        lu = self.lu
        return sla.lu_solve(lu, b.astype(lu[0].dtype, copy=False), trans=1, check_finite=False).astype(
            np.float64, copy=False
        )


class SwitchedLU:
    """LU of ``M = A P_F - B P_S`` of a :class:`SwitchedOperator`, reused as the set moves.

    ``solve([r1; r2])`` solves the switched system: ``p_S = r2_S``, ``v_F = r2_F`` and
    ``M y = r1 - A[:, S] r2_S`` for ``y = (p_F, v_S)``, the coupling taken on the entries
    of ``r2_S`` above 1e-6 of the largest (a recycled direction of an earlier step breaks
    the new constraints at the few nodes that switched), its ``G C`` part from those
    columns of a dense ``C`` and left out otherwise: exact when ``r2_S = 0``, as for every
    right-hand side of a step, and a preconditioner otherwise.  :meth:`adapt` updates it to a later step
    whose set differs in ``k`` nodes by a rank-``k`` Woodbury correction (the changed
    columns, taken from the later step's operator), so the preconditioner stays exact in
    the switched columns while the cavity's edge moves; beyond ``max_changes`` it asks
    for a new factorization.
    """

    max_changes = 64

    def __init__(self, op: SwitchedOperator, dtype, t):
        n = op.n
        S = np.flatnonzero(op.switched)
        A = op.base.matrix(dtype=dtype)
        if S.size:
            A[:, S] = -op.B[:, S].toarray()
        self.lu = DenseLU(A, t)
        self.switched = op.switched.copy()
        self.n = n
        self.op = op
        self._corr = None

    def adapt(self, op: SwitchedOperator) -> bool:
        """Use this factor for ``op``; False when its set changed too much (refactor)."""
        self.op = op
        delta = np.flatnonzero(op.switched != self.switched)
        if delta.size == 0:
            self._corr = None
            return True
        if delta.size > self.max_changes:
            return False
        # M_now[:, j] - M_factor[:, j] on the changed columns: +-(A[:, j] + B[:, j])
        sign = np.where(op.switched[delta], -1.0, 1.0)
        U = (op.base.columns(delta) + op.B[:, delta].toarray()) * sign
        Z = self.lu.solve(U)
        small = np.eye(delta.size) + Z[delta]
        try:
            small_lu = sla.lu_factor(small, check_finite=True)
        except (ValueError, np.linalg.LinAlgError):
            return False
        self._corr = (delta, Z, small_lu)
        return True

    def _solve_M(self, r):
        y = self.lu.solve(r)
        if self._corr is not None:
            delta, Z, small_lu = self._corr
            y = y - Z @ sla.lu_solve(small_lu, y[delta])
        return y

    def solve(self, b):
        n, op = self.n, self.op
        S = op.switched
        r1, r2 = b[:n], b[n:]
        rhs = r1
        big = S & (np.abs(r2) > 1e-6 * float(np.abs(b).max()))
        if big.any():  # the coupling A[:, S] r2_S: exactly on the entries that matter
            j = np.flatnonzero(big)
            rhs = r1 - op.base.D[:, j] @ r2[j]
            C = op.base.C
            if is_dense(C):  # dense: the columns' product, ne x len(j)
                rhs = rhs - op.base.G @ (C[:, j] @ r2[j])
        y = self._solve_M(rhs)
        x = np.empty(2 * n)
        x[:n] = np.where(S, r2, y)
        x[n:] = np.where(S, y, r2)
        return x


class _BorderC:
    """``C`` of a :class:`BorderedOperator` on ``[p; eta]``: ``C p + eta``, the film's change
    (eta moves the whole film, in ``C``'s units), so ``G (C z)`` carries the column ``G 1``
    and the film check sees hc as well as p."""

    def __init__(self, C, n):
        self.C, self.n = C, n
        self.shape = (C.shape[0], n + 1)

    def __matmul__(self, z):
        return self.C @ z[: self.n] + z[self.n]

    @staticmethod
    def tail(w):
        """The column of ``w^T C`` for eta (:meth:`RecycledGCR._tracked_ok`'s probes)."""
        return w.sum(axis=1)


class BorderedOperator:
    """A step whose ``hc`` is one more unknown (an imposed load, a free indenter), bordered::

        [ A       G 1 ] [ p   ]   [ b ]
        [ -l^T    c   ] [ eta ] = [ f ]

    ``A`` the dense or fast :class:`StepOperator` ``inner`` (its held rows included), or a
    :class:`SwitchedOperator` (JFO's cavitated nodes, whose gas follows the pressure), eta
    hc's change from the last step over the film's scale (``A p + hc G 1 / scale`` is the
    step's gap term), ``-l . p + c eta = f`` the control's row
    (:meth:`femehl.solver.parts.ImposedLoad.border`, scaled by the stepper to the
    right-hand side's size).  ``C`` is
    :class:`_BorderC`, so the Krylov solver needs nothing of its own for it; the
    preconditioner (and the direct solve) is ``inner``'s LU with the border's Schur
    complement (:class:`BorderedLU`).  One solve a step instead of two (``A x1 = b``,
    ``A x2 = G 1``)."""

    def __init__(self, inner: StepOperator, row, corner: float, column=None):
        self.inner = inner
        self.n = n = inner.D.shape[0]
        self.row = np.asarray(row, dtype=float)
        self.corner = float(corner)
        if column is None:  # G 1: the rows of A for eta (the stepper has it: its check's)
            column = inner.G @ np.ones(inner.G.shape[1])
        self.column = np.asarray(column, dtype=float).ravel()
        self.key = inner.key
        self.held = getattr(inner, "held", None)  # the rows a preconditioner refresh watches
        self.switched = getattr(inner, "switched", None)
        self.C = _BorderC(inner.C, n)

    @property
    def dense(self) -> bool:
        return self.inner.dense

    @property
    def fast(self) -> bool:
        return self.inner.fast

    @cached_property
    def D(self):
        last = sp.csr_matrix(np.append(-self.row, self.corner)[None, :])
        return sp.vstack([sp.hstack([self.inner.D, sp.csr_matrix((self.n, 1))]), last], format="csr")

    @cached_property
    def G(self):
        G = self.inner.G
        return sp.vstack([G, sp.csr_matrix((1, G.shape[1]))], format="csr")

    apply = StepOperator.apply  # D Z + G C Z, with this operator's D, G and C

    def factorize(self, dtype, t):
        return BorderedLU(self.inner.factorize(dtype, t), self, t)


class BorderedLU:
    """The preconditioner (or the direct solve) of a :class:`BorderedOperator` from the LU
    ``lu`` of its inner operator: ``w = M^-1 G 1`` and the Schur complement ``s = c + l . w``
    of the step it follows (:meth:`follow`: one more solve with ``M`` a step), then
    ``y = M^-1 r``, ``eta = (r_eta + l . y) / s``, ``z = y - eta w``."""

    def __init__(self, lu, op: BorderedOperator, t: float):
        self.lu = lu
        self.follow(op, t)

    def follow(self, op: BorderedOperator, t: float) -> None:
        """Take the border of ``op`` (the step's column, row and corner)."""
        self.row, self.n = op.row, op.n
        self.w = self.lu.solve(op.column)
        self.s = op.corner + float(self.row @ self.w)
        if not np.isfinite(self.s) or self.s == 0.0:
            raise SingularSystemError(
                f"step at t = {t:.6g}: the load row is singular (the film does not respond to hc).", t=t
            )

    def solve(self, r):
        n = self.n
        y = self.lu.solve(r[:n])
        eta = (r[n] + float(self.row @ y)) / self.s
        return np.append(y - eta * self.w, eta)


#: a tracked C x whose error exceeds this (relative, by the random probes) is formed instead:
#: above the rounding of a combination of nearly collinear recycled solutions at small dt
#: (1e-9 to 5e-9 measured on the paper case at dt = 0.0025, where the old solver accepted its
#: solutions with it; forming C x there only exposed it and forced a direct solve per step),
#: far below the drift that made a free indenter's film wrong (1e-4)
_TRACK_RTOL = 1e-7
#: without probes (the fast operator): C x is formed after this many generations of tracking
_MAX_TRACKED = 8
_PROBES = 2

#: name -> linear solver class
LINEAR_SOLVERS = Registry("linear solver", stamp="name")
#: class decorator adding a linear solver to :data:`LINEAR_SOLVERS`: ``@register_linear_solver("lu")``
register_linear_solver = LINEAR_SOLVERS.register


def make_linear_solver(name, **options):
    if not isinstance(name, str) or name not in LINEAR_SOLVERS:
        raise SceneError(f"linear_solver must be one of {sorted(LINEAR_SOLVERS)}, got {name!r}.")
    return LINEAR_SOLVERS[name](**options)


def _singular(t, what):
    return SingularSystemError(
        f"step at t = {t:.6g}: {what}. Try a smaller dt or a finer discretization.", t=t
    )


def _dense_lu(A, t):
    try:
        # A is C-ordered, so A.T is Fortran-ordered: LAPACK factors it in place (LU of A^T)
        lu = sla.lu_factor(A.T, overwrite_a=True, check_finite=True)
    except (ValueError, np.linalg.LinAlgError) as exc:
        raise _singular(t, f"cannot factor the system ({exc})") from None
    if np.any(np.abs(np.diag(lu[0])) == 0.0):
        raise _singular(t, "the linear system is singular (zero pivot)")
    return lu


def _sparse_lu(A, t):
    try:
        return spla.splu(A)
    except RuntimeError as exc:
        raise _singular(t, f"the sparse system is singular ({exc})") from None


def nested_dissection(A) -> np.ndarray:
    """METIS nested-dissection ordering of the symmetrized pattern of ``A`` (pymetis).

    On the fast path's near-field matrices it keeps the LU fill growing like log N
    (400 -> 661 entries per row from 5.8k to 45k unknowns; SuperLU's own COLAMD 366 ->
    1163), so the preconditioner's set-up and solves stay O(N log N).
    """
    import pymetis

    S = (abs(A) + abs(A).T).tocsr()
    S.setdiag(0)
    S.eliminate_zeros()
    S.sort_indices()
    order = pymetis.nested_dissection(pymetis.CSRAdjacency(S.indptr, S.indices))
    return np.asarray(order[0] if isinstance(order, tuple) else order, dtype=np.int64)


class PermutedLU:
    """SuperLU of ``A[perm][:, perm]`` in the natural order: ``solve(b)`` solves ``A x = b``.

    ``dtype``: the precision of the factors (the fast path's preconditioner factors in
    single precision, :attr:`RecycledGCR.precond_dtype`: 0.23 s against 0.36 s and 5.8
    against 7.5 ms per solve on 27,640 elements, same nested-dissection fill).
    """

    def __init__(self, A, perm, t, dtype=np.float64):
        self.perm = perm
        self.dtype = np.dtype(dtype)
        try:
            self.lu = spla.splu(sp.csc_matrix(A[perm][:, perm], dtype=dtype), permc_spec="NATURAL")
        except RuntimeError as exc:
            raise _singular(t, f"the sparse system is singular ({exc})") from None

    def solve(self, b):
        x = np.empty_like(b)
        x[self.perm] = self.lu.solve(b[self.perm].astype(self.dtype, copy=False))
        return x

    @property
    def fill(self) -> int:
        """Entries of the factors."""
        return int(self.lu.nnz)


#: the fast path's nested-dissection ordering is kept while the near field's pattern moves
#: (a Reynolds step's held rows, a rough film's columns near contact: every step on the
#: rough PDMS ball, where METIS took 15.4 s of a 190 s run, 0.15 s a refresh, fitted
#: level 0.85, 14,860 elements), and made again when an LU on it holds more than this
#: times the entries of the first LU on it
ORDER_FILL = 1.2


@dataclass
class _Ordering:
    """A nested-dissection ordering of near-field matrices of ``shape`` (:data:`ORDER_FILL`)."""

    shape: tuple
    perm: np.ndarray
    fill: int | None = None  # entries of the first LU on it
    grown: bool = False  # an LU on it grew past ORDER_FILL * fill: order again

    def saw(self, fill: int) -> None:
        if self.fill is None:
            self.fill = fill
        else:
            self.grown = fill > ORDER_FILL * self.fill


class TwoLevel:
    """Near-field LU plus a coarse Galerkin correction: ``solve(r)`` approximates ``A^-1 r``.

    With ``P`` (n x m) a coarse P1 space (:func:`femehl.elastic.coarse.coarse_prolongation`)
    and ``AP = A P = D P + G (C P)`` (:meth:`StepOperator.coarse_system`: ``C P`` formed
    once at set-up, sparse work per refresh), the coarse solve comes first and the
    near-field LU ``N`` smooths what is left: ``y = (P^T A P)^-1 P^T r``,
    ``z = P y + N^-1 (r - AP y)``.  No product with ``C`` per application (``A P y`` is
    ``AP @ y``).  The near-field LU misses the smooth far field of the 1/r kernel; the
    coarse space carries it.  Measured on the paper sphere (11,450 elements, fresh
    solves to 1e-9 without recycling): 13-19 iterations with ``N`` alone, 5-7 with
    ``m`` = 400 coarse nodes; the coarse-after and the additive forms did worse (8-10,
    14-21).
    """

    def __init__(self, near, P, AP, t):
        self.near = near
        self.P = P
        self.AP = AP  # single precision: read once per application
        # P^T as CSR: row-wise, the same sums as P.T @ AP (CSC), which on a freshly formed
        # AP took 0.46 s against 0.05 s on 45,156 elements (a third of each refresh)
        self._Pt = P.T.tocsr()
        Ac = np.asarray(self._Pt @ AP, dtype=float)
        try:
            self.lu = sla.lu_factor(Ac, check_finite=True)
        except (ValueError, sla.LinAlgError) as exc:
            raise _singular(t, f"the coarse system is singular ({exc})") from None

    def solve(self, r):
        y = sla.lu_solve(self.lu, self._Pt @ r)
        APy = self.AP @ y.astype(np.float32)  # in single precision: no double copy of AP
        return self.P @ y + self.near.solve(r - APy)


@register_linear_solver("lu")
class DirectSolver:
    """A new LU of ``A`` every step (the paper's direct solve), shared by its right-hand sides."""

    #: a direct solve has no residual to tighten (the stepper sets it for every solver)
    rtol_scale = 1.0

    def __init__(self):
        self.info = {"factorizations": 0, "factor_s": 0.0}
        self.residuals: list = []  # relative true residuals of the last step (where cheap)

    def factor(self, op: StepOperator, t: float):
        t0 = time.perf_counter()
        if op.dense:
            solve = op.factorize(np.float64, t).solve
        else:
            A = op.matrix()
            lu = _sparse_lu(A, t)

            def solve(b):  # sparse: the true residual costs nothing, record it
                x = lu.solve(b)
                self.residuals.append(float(np.linalg.norm(A @ x - b) / np.linalg.norm(b)))
                return x

        self.info["factorizations"] += 1
        self.info["factor_s"] += time.perf_counter() - t0
        return solve

    def solve(self, op: StepOperator, rhs: list, t: float) -> list:
        """``[(x, C x or None), ...]`` for each right-hand side."""
        solve = None
        out = []
        self.residuals = []
        for b in rhs:
            if not np.any(b):
                out.append((np.zeros_like(b), None))
                continue
            solve = self.factor(op, t) if solve is None else solve
            out.append((solve(b), None))
        return out


#: refresh the preconditioner when ``c_0 = a0/dt`` fell by more than this fraction of the
#: new ``c_0`` (3: to below a quarter of the factorized one, ``dt`` more than quadrupled).
#: Smaller changes, and any rise of ``c_0`` (a smaller ``dt``: a rejected trial, the restart
#: at a breakpoint; the squeeze term ``c_0 F C`` the LU holds then dominates more), are left
#: to the cost balancing.  Why a factor q of ``dt`` costs little: with the LU of
#: ``D + c F C`` and the step's ``D + (c/q) F C``, the preconditioned matrix is
#: ``I/q + (1 - 1/q) P^-1 D``, whose spectrum lies between 1/q and 1 where ``P^-1 D``'s lies
#: in [0, 1]: a condition number of at most q, a few iterations against the refresh's 40-110
#: (:func:`factor_cost`).  An adaptive run's ``dt`` drifts by a few % a step but grows by
#: 2-4 a step after t = 0 and after a breakpoint: at 0.1 the paper case (fitted level 0.5,
#: 11,472 elements, adaptive BDF2 at tol 3.1e-4) refreshed 74 times in 753 steps, 93 s of
#: its 164 s.  The paper case's automatic answer (5,992 cells, 2026-12-07, one BLAS thread,
#: its run alone, two rounds each): at 1, 22 refreshes, 825 iterations, 12.7 s; at 2, 3, 5,
#: 7 and none, 12 / 14 / 12 / 14 / 11 refreshes, 884 / 839 / 911 / 956 / 1,011 iterations,
#: 10.8 / 10.7-11.0 / 11.0 / 12.0 / 11.0-11.2 s.  The layer's (14,030 cells, LU 2.4 s):
#: 17 refreshes and 92.4 s at 1, 12 and 81.5 s at 3.  The load-controlled sphere and an
#: ellipsoid on the fast operator: within 1 % either way.  A fixed-dt run changes ``c_0``
#: only at its first BDF2 step (``a0`` from 1 to 3/2)
KEY_CHANGE = 3.0

#: the preconditioner's refresh balances its cost against the iterations it saves, both
#: counted in preconditioned iterations (a model, not the clock: with measured times two
#: runs of the same scene refreshed 26, 27 and 31 times and their films differed by 1e-4,
#: the adaptive steps following the solves' rounding).  Dense path: a single-precision LU
#: of n unknowns against an iteration's ``C z`` of ne x n, ``DENSE_KAPPA n^2 / ne`` and at
#: least ``DENSE_FACTOR_MIN``: twice the measured ratio (one BLAS thread, this machine: 24,
#: 17, 24, 39 iterations at n = 800, 1,500, 3,000, 5,000 with ne = 2 n), which made the
#: paper case's automatic answer (5,986 cells) 18.2 s against 19.1 s at the ratio itself
#: (15 refreshes and 855 iterations against 24 and 753; means of 3 and 4 runs); fast path:
#: ``FAST_FACTOR`` (the near-field LU and the coarse correction: 7.1 and 8.1 on 11,450 and
#: 23,268 elements)
DENSE_KAPPA, DENSE_FACTOR_MIN, FAST_FACTOR = 0.032, 40.0, 8.0


def factor_cost(op) -> float:
    """The preconditioner's factorization of ``op`` in preconditioned iterations."""
    if op.fast:
        return FAST_FACTOR
    n, ne = op.D.shape[0], max(1, op.C.shape[0])
    return max(DENSE_FACTOR_MIN, DENSE_KAPPA * n * n / ne)


def _key_moved(factored: float, now: float) -> bool:
    """``c_0`` fell by more than ``KEY_CHANGE`` times its new value since the LU."""
    return factored - now > KEY_CHANGE * abs(now)


#: refresh the preconditioner before a solve when the rows a step replaced (the Reynolds
#: condition's held rows, :meth:`StepOperator.with_fixed`; a JFO step's switched unknowns,
#: :class:`SwitchedOperator`, where its LU cannot follow them, :meth:`SwitchedLU.adapt`)
#: differ from the factorized ones in more than this times :func:`factor_cost` rows.  Each
#: changed row is a rank-one error of the preconditioner, and they cost Krylov iterations
#: beyond their number, while the cost balancing refreshed only after such a solve.  First
#: solves after 1-4 / 5-19 / 20-49 / 50-99 changed rows, fast operator:
#: the rough PDMS ball (``examples/pdms_ball.toml``, fitted level 1, 10,786 elements, to
#: t = 3), 11 / 20 / 98 / 93 preconditioned iterations against 5.8 with none; the paper
#: sphere with JFO (fitted level 0.5, 11,450 elements, to t = 2), 18 / 32 / 48 (20-49)
#: against 7.5
HELD_CHANGE = 1.0
#: ... and in no more rows than the solve's iteration cap over this (a stale preconditioner
#: costs about 2-3 iterations per changed row: 12 rows took 27 iterations on the rough PDMS
#: ball's dense path, fitted level 1.15, 8,222 elements, where ``factor_cost`` is 67 rows
#: and the cap 30, so every step whose Reynolds set moved in 13-37 rows spent 30
#: iterations on a solve that failed, then refreshed anyway)
ROW_ITERATIONS = 3.0


def _replaced_rows(op):
    """The rows ``op`` replaced: held (:meth:`StepOperator.with_fixed`) or switched
    (:class:`SwitchedOperator`), sorted; None if none."""
    held = getattr(op, "held", None)
    if held is not None:
        return np.sort(np.asarray(held, dtype=np.int64))
    switched = getattr(op, "switched", None)
    return None if switched is None else np.flatnonzero(switched)


def _rows_moved(factored, now, cost: float) -> bool:
    """The replaced rows ``now`` differ from the ``factored`` ones in more than
    ``HELD_CHANGE * cost`` rows (either may be None: none)."""
    a = np.zeros(0, dtype=np.int64) if factored is None else factored
    b = np.zeros(0, dtype=np.int64) if now is None else now
    if np.array_equal(a, b):
        return False
    return np.setxor1d(a, b, assume_unique=True).size > HELD_CHANGE * cost


@dataclass
class _Factor:
    lu: object  # the preconditioner: DenseLU, SwitchedLU or PermutedLU (``.solve(r)``)
    key: float  # op.key of the factorized matrix
    total: float  # cost of this factor's cycle in iterations: factorization + iterations
    solves: int = 0  # solves of this cycle
    stale: bool = False  # refresh at the next solve
    rows: np.ndarray | None = None  # the factorized matrix's replaced rows (_replaced_rows)


#: the film ratio min(d) / max|w| below which the Krylov residual is tightened in
#: proportion (:func:`film_rtol_scale`), and the smallest factor
FILM_RTOL_REF = 1e-2
FILM_RTOL_FLOOR = 1e-3


def film_rtol_scale(d, w) -> float:
    """Factor on the Krylov ``rtol`` for a film ``d`` with deflection ``w`` (last state).

    The solve's error moves the film by about ``rtol`` times the deflection, whatever the
    film: so a film much thinner than the deflection carries a *relative* error
    ``rtol max|w| / min(d)`` that grows as it thins, and near a closing it is larger than
    the adaptive controller's time-error tolerance (measured: the stress case beta = 2,
    h0 = 0.01, T = 0.1 on about 16,000 elements with the fast operator stopped at the step
    floor with a film of 4.3e-4 whose error estimate 2.2e-4 was the solve's noise; with
    rtol = 1e-12 it closed steadily at t = 2.619).  The factor keeps that relative error
    where it is at ``min(d) = FILM_RTOL_REF max|w|`` (1 above it, so the paper case and
    thicker films are unchanged), down to :data:`FILM_RTOL_FLOOR` (1e-12 with the fast
    operator's 1e-9).
    """
    d = np.asarray(d, dtype=float)
    w = np.asarray(w, dtype=float)
    if d.size == 0 or w.size == 0:
        return 1.0
    dmin = float(np.min(d))
    wmax = float(np.max(np.abs(w)))
    if not (np.isfinite(dmin) and np.isfinite(wmax)) or wmax <= 0.0 or dmin >= FILM_RTOL_REF * wmax:
        return 1.0
    return float(max(FILM_RTOL_FLOOR, max(dmin, 0.0) / (FILM_RTOL_REF * wmax)))


#: where the film is thin (:func:`film_rtol_scale` below 1) or may close (a floor), the
#: solve's film error is also checked, at most FILM_SOLVE_REL times the film's scale
#: (:func:`film_tolerances`, ``RecycledGCR._film_check``)
FILM_SOLVE_REL = 1e-6


def film_tolerances(d, w, floor: float = 0.0, scale: float = 1.0) -> tuple[float, float | None]:
    """The solve's tolerances for a step from the film ``d`` with deflection ``w``: the factor
    on ``rtol`` (:func:`film_rtol_scale`) and, where it is below 1 or the film may close
    (``floor > 0``, the film scale of the step error: a rough surface's sigma), the largest
    film error ``|scale C e|`` allowed, :data:`FILM_SOLVE_REL` times the thinnest film, at
    least ``floor``; None otherwise (no check)."""
    factor = film_rtol_scale(d, w)
    film = max(float(np.min(d)), floor) if np.size(d) else 0.0
    if (factor >= 1.0 and floor <= 0.0) or not (np.isfinite(film) and film > 0.0 and scale != 0.0):
        return factor, None
    return factor, FILM_SOLVE_REL * film / abs(scale)


@register_linear_solver("gmres")
class RecycledGCR:
    """Recycled, LU-preconditioned minimal residual (docs/design.md section 3.2).

    Parameters
    ----------
    rtol : float, optional
        Relative residual every system is solved to, in (0, 1e-2); default 1e-8, and
        1e-9 with the fast operator.
    refactor_after : int, optional
        Refresh the LU when a solve needed more than this many preconditioned iterations;
        default (None): by cost balancing.
    recycle : int, default: 8
        Recycled directions kept between solves (0: none).
    max_krylov : int, optional
        Preconditioned iterations before falling back to a direct solve; default 30, and
        200 with the fast operator (its sparse preconditioner needs more, and there is
        no direct solve to fall back to).
    """

    #: it solves a :class:`BorderedOperator` (an imposed load's step) in one Krylov solve
    borders = True

    def __init__(
        self,
        rtol: float | None = None,
        refactor_after: int | None = None,
        recycle: int = 8,
        max_krylov: int | None = None,
    ):
        if rtol is not None:
            rtol = check_in_range("rtol", rtol, 0.0, 1e-2, open_low=True, open_high=True)
        if refactor_after is not None and (
            isinstance(refactor_after, bool) or not isinstance(refactor_after, int) or refactor_after < 1
        ):
            raise SceneError(f"refactor_after must be an integer >= 1 or None, got {refactor_after!r}.")
        if isinstance(recycle, bool) or not isinstance(recycle, int) or recycle < 0:
            raise SceneError(f"recycle must be an integer >= 0, got {recycle!r}.")
        if max_krylov is not None and (
            isinstance(max_krylov, bool) or not isinstance(max_krylov, int) or max_krylov < 1
        ):
            raise SceneError(f"max_krylov must be an integer >= 1 or None, got {max_krylov!r}.")
        self._rtol = rtol
        self.rtol_scale = 1.0  # set per step by the stepper: film_tolerances
        self.film_atol: float | None = None  # the film error allowed (film_tolerances), or no check
        self.refactor_after = refactor_after
        self.recycle = recycle
        self.max_krylov = max_krylov
        self._fast = False
        self._order: _Ordering | None = None  # the fast path's nested-dissection ordering
        self.precond_dtype = np.float32  # the LU is a preconditioner only: single precision
        self.direct = DirectSolver()
        self.factor: _Factor | None = None
        self.solutions: list = []  # recent (x, C x)
        self._solution_ages: list = []  # generations of tracking behind their C x
        self._probe = None  # (w, w^T C): checks a tracked C x at the cost of two dot products
        self.directions: list = []  # recent preconditioned (z, C z)
        self.history: list = []  # relative residuals of the last solve
        self.info = {"factorizations": 0, "factor_s": 0.0, "krylov_iterations": 0, "krylov_s": 0.0}
        self._own_factorizations = 0  # preconditioner LUs (the direct fallback counts its own)
        self._own_factor_s = 0.0

    def solve(self, op: StepOperator, rhs: list, t: float) -> list:
        self.residuals = []
        if not (op.dense or op.fast):  # nothing dense to save: solve directly
            out = self.direct.solve(op, rhs, t)
            self.residuals = self.direct.residuals
            self._sync()
            return out
        G = op.G
        self._fast = op.fast
        return [self._solve_one(op, G, b, t) for b in rhs]

    def _sync(self):
        self.info["factorizations"] = self._own_factorizations + self.direct.info["factorizations"]
        self.info["factor_s"] = self._own_factor_s + self.direct.info["factor_s"]

    def _solve_one(self, op, G, b, t):
        bnorm = float(np.linalg.norm(b))
        if bnorm == 0.0:
            return np.zeros_like(b), None
        f = self.factor
        fresh = f is None or f.stale or _key_moved(f.key, op.key)
        fresh = fresh or isinstance(f.lu, BorderedLU) != isinstance(op, BorderedOperator)
        bordered = not fresh and isinstance(f.lu, BorderedLU)
        lu, inner = (f.lu.lu, op.inner) if bordered else (None if fresh else f.lu, op)
        if not fresh and hasattr(lu, "adapt"):  # a switched step: follow its set
            fresh = not lu.adapt(inner)
        elif not fresh:
            fresh = _rows_moved(f.rows, _replaced_rows(op), self._row_budget(op))
        if not fresh and bordered:  # a bordered step: its own border, on the LU as it is now
            f.lu.follow(op, t)
        if fresh:
            # drop this frame's reference first: _refactor frees the old factor before it
            # forms the new matrix, which a live local would keep (one n x n array more at
            # the dense path's peak: 20.9 against 18.9 GB over the whole paper case on
            # 44,792 elements)
            f = None
            f = self._refactor(op, t)
        x, Cx, gen, its, dirs = self._timed_krylov(op, G, b, bnorm, f)
        if x is None and fresh and (self.solutions or self.directions):
            # the recycled space's rounding, not the preconditioner: the true residual stalls
            # while the recursive one falls to 1e-13 (a combination of nearly collinear
            # solutions of earlier steps at small dt: a free indenter's first steps on the
            # fast operator stalled at 7e-8 against rtol 1e-9 and stopped the run)
            self.solutions, self._solution_ages, self.directions = [], [], []
            self.info["recycle_resets"] = self.info.get("recycle_resets", 0) + 1
            x, Cx, gen, its, dirs = self._timed_krylov(op, G, b, bnorm, f)
        if x is None:
            if fresh and op.fast:
                raise SingularSystemError(
                    f"step at t = {t:.6g}: the Krylov solve with the fast elastic operator did not "
                    f"reach rtol = {self.rtol:g} in {self._max_its(op)} iterations even with a fresh "
                    "preconditioner. Try a smaller dt, max_krylov larger, or operator='dense' if the "
                    "mesh fits.",
                    t=t,
                )
            if fresh:  # even a fresh preconditioner failed: solve directly in double
                x = self.direct.solve(op, [b], t)[0][0]
                self._sync()
                return x, None
            f.stale = True
            f = None  # the retry refreshes the factor: hold no reference to the old one
            return self._solve_one(op, G, b, t)
        self._remember(x, Cx, gen, dirs)
        if self.refactor_after is not None:
            f.stale = its > self.refactor_after
        else:
            f.total += its  # in preconditioned iterations: no clock, the same run every time
            f.solves += 1
            f.stale = its > f.total / f.solves
        return x, Cx

    def _timed_krylov(self, op, G, b, bnorm, f):
        t0 = time.perf_counter()
        x, Cx, gen, its, dirs = self._krylov(op, G, b, bnorm, f)
        self.info["krylov_iterations"] += its
        self.info["krylov_s"] += time.perf_counter() - t0
        return x, Cx, gen, its, dirs

    @property
    def rtol(self) -> float:
        """The relative residual of this step: the base one (default by dense / fast, of the
        last operator seen) times :attr:`rtol_scale` (:func:`film_rtol_scale`)."""
        base = self._rtol if self._rtol is not None else (1e-9 if self._fast else 1e-8)
        return base * self.rtol_scale

    def _row_budget(self, op) -> float:
        """How many changed replaced rows a stale preconditioner is left to absorb
        (:data:`HELD_CHANGE`): :func:`factor_cost`, and no more than this solve's iteration
        cap allows at :data:`ROW_ITERATIONS` each."""
        return min(factor_cost(op), self._max_its(op) / ROW_ITERATIONS)

    def _max_its(self, op):
        if self.max_krylov is not None:
            return self.max_krylov
        return 200 if op.fast else 30

    def _refactor(self, op, t):
        """The preconditioner: single-precision LU of the current A, or with the fast
        operator the sparse LU of its near-field part."""
        self.factor = None  # free the old factor before forming the new A
        t0 = time.perf_counter()
        outer = op
        if isinstance(op, BorderedOperator):  # a bordered step: its inner operator's LU
            op = op.inner
        if op.fast:
            A = op.near_matrix()
            if self._order is None or self._order.shape != A.shape or self._order.grown:
                self._order = _Ordering(A.shape, nested_dissection(A))
            lu = PermutedLU(A, self._order.perm, t, self.precond_dtype)
            self._order.saw(lu.fill)
            coarse = op.coarse_system()
            if coarse is not None:  # the smooth far field: a coarse Galerkin correction
                lu = TwoLevel(lu, *coarse, t)
        else:
            lu = op.factorize(self.precond_dtype, t)
        if outer is not op:
            lu, op = BorderedLU(lu, outer, t), outer
        self._own_factorizations += 1
        self._own_factor_s += time.perf_counter() - t0
        self._sync()
        self.factor = _Factor(lu, op.key, total=factor_cost(op), rows=_replaced_rows(op))
        return self.factor

    def _precondition(self, r):
        return self.factor.lu.solve(r)

    def _krylov(self, op, G, b, bnorm, f):
        """Minimal residual over recycled + preconditioned directions.

        Returns ``(x, C x, generations, preconditioned iterations, new directions)``, or
        ``x = None`` when ``rtol`` was not reached in ``max_krylov`` iterations.  ``C x`` is
        tracked (``y @ CZ``, no product) and checked (:meth:`_tracked_ok`); it is formed
        when the check fails (``info["exact_products"]``).
        """
        C, D = op.C, op.D
        tol = self.rtol * bnorm
        rec = self.solutions + self.directions
        # generations of tracking behind each recycled C z (a direction's was formed: 0)
        rec_age = self._solution_ages + [0] * len(self.directions)
        if any(z.size != b.size for z, _ in rec):  # a bordered step after one that was not
            rec_age = [a for (z, _), a in zip(rec, rec_age, strict=True) if z.size == b.size]
            rec = [(z, cz) for z, cz in rec if z.size == b.size]
        max_its = self._max_its(op)
        m = len(rec) + max_its
        n, ne = b.size, C.shape[0]
        Z = np.empty((m, n))  # row j: direction z_j
        CZ = np.empty((m, ne))  # row j: C z_j
        Q = np.empty((m, n))  # row j: orthonormal basis of A span(Z)
        R = np.zeros((m, m))
        g = np.zeros(m)
        age = np.zeros(m, dtype=np.int64)  # generations of tracking behind CZ[j]
        k = 0
        r = b.copy()
        if rec:
            Zr = np.array([z for z, _ in rec])
            CZr = np.array([cz for _, cz in rec])
            AZ = op.apply(Zr.T, CZr.T, G)  # sparse work only
            scale = np.linalg.norm(AZ, axis=0)
            scale[scale == 0.0] = 1.0
            q, rr, piv = sla.qr(AZ / scale, mode="economic", pivoting=True)
            dg = np.abs(np.diag(rr))
            k = int(np.count_nonzero(dg > 1e-8 * dg[0])) if dg.size and dg[0] > 0 else 0
            sel = piv[:k]
            Z[:k] = Zr[sel] / scale[sel, None]
            CZ[:k] = CZr[sel] / scale[sel, None]
            age[:k] = np.asarray(rec_age, dtype=np.int64)[sel]
            Q[:k] = q[:, :k].T
            R[:k, :k] = rr[:k, :k]
            for _ in range(2):  # r = b - Q Q^T b, reorthogonalized
                h = Q[:k] @ r
                r -= h @ Q[:k]
                g[:k] += h
        its = 0
        k_rec = k
        hist = [float(np.linalg.norm(r)) / bnorm]
        ahead = None  # a film check's preconditioned correction (z, C z): the next direction
        while True:
            if ahead is None and (hist[-1] <= 0.5 * self.rtol or its >= max_its):
                if k == 0:
                    return None, None, 0, its, []
                y = sla.solve_triangular(R[:k, :k], g[:k])
                x = y @ Z[:k]
                Cx = y @ CZ[:k]  # tracked: C is linear, so no extra product
                if not self._tracked_ok(C, x, Cx, age[:k]):
                    # form C x: a tracked one inherits its recycled pairs' rounding, amplified
                    # by the combination, generation after generation (measured: 1e-4
                    # relative after 70 steps of a free indenter, films wrong by 10 %)
                    Cx = C @ x
                    self.info["exact_products"] = self.info.get("exact_products", 0) + 1
                    gen = 0
                else:
                    gen = int(age[:k].max()) + 1
                rt = b - D @ x - G @ Cx  # the TRUE residual
                res = float(np.linalg.norm(rt))
                hist.append(res / bnorm)
                self.history = hist
                reached = np.isfinite(res) and res <= tol
                if reached and self.film_atol is not None and its < max_its:
                    ahead = self._film_check(C, rt)
                if reached and ahead is None:
                    self.residuals.append(res / bnorm)
                    return x, Cx, gen, its, [(Z[j].copy(), CZ[j].copy()) for j in range(k_rec, k)]
                if its >= max_its or not np.isfinite(res):
                    return None, None, 0, its, []
                r = rt - (Q[:k] @ rt) @ Q[:k]  # continue from the true residual
            if ahead is None:
                z = self._precondition(r)
                cz = C @ z  # the one dense (or hierarchical) product
            else:  # the film check's correction, already formed
                (z, cz), ahead = ahead, None
            q = D @ z + G @ cz
            h = np.zeros(k)
            for _ in range(2):
                hh = Q[:k] @ q
                q -= hh @ Q[:k]
                h += hh
            nq = float(np.linalg.norm(q))
            its += 1
            if not np.isfinite(nq) or nq == 0.0:
                return None, None, 0, its, []
            Q[k] = q / nq
            R[:k, k] = h
            R[k, k] = nq
            Z[k] = z
            CZ[k] = cz
            g[k] = Q[k] @ r
            r -= g[k] * Q[k]
            k += 1
            hist.append(float(np.linalg.norm(r)) / bnorm)

    def _film_check(self, C, rt):
        """None when the solve's film error is within :attr:`film_atol`, else the correction
        ``(z, C z)`` that measured it, for the next direction.

        ``z = M^-1 r`` of the true residual estimates the solution's error as well as the
        preconditioner ``M`` approximates the matrix, and ``C z`` the film's (its largest
        entry).  Where the residual says little about the film (asperities in deep contact
        on a rough surface: a relative residual of 3e-11 left films wrong by 6e-4 sigma),
        this is what keeps the step error estimate free of the solve's noise.
        """
        z = self._precondition(rt)
        cz = C @ z
        self.info["film_checks"] = self.info.get("film_checks", 0) + 1
        if float(np.max(np.abs(cz), initial=0.0)) <= self.film_atol:
            return None
        return z, cz

    def _tracked_ok(self, C, x, Cx, ages) -> bool:
        """Is the tracked ``C x`` within ``_TRACK_RTOL`` of the true one?

        Freivalds' check: with fixed random probes ``w`` (Gaussian, ``_PROBES`` of them) and
        ``u = w^T C`` formed once, ``w . (C x)_tracked - u . x = w . e`` for the error ``e``;
        for a Gaussian ``w`` it is ``|e|`` times a standard normal, so ``|e|`` above the
        tolerance is caught unless every probe is nearly orthogonal to it.  Two dot products
        per probe instead of an ``elements x unknowns`` product.  A fast (hierarchical)
        ``C`` has no transpose here: its ``C x`` is formed every ``_MAX_TRACKED``
        generations instead.
        """
        bordered = isinstance(C, _BorderC)
        dense = C.C if bordered else C
        leading = dense.shape[1] if isinstance(dense, _Leading) else None
        dense = dense.C if isinstance(dense, _Leading) else dense
        if not is_dense(dense):
            return ages.size == 0 or int(ages.max()) < _MAX_TRACKED
        n = x.size
        if self._probe is None or self._probe[1].shape[1] != n:
            w = np.random.default_rng(20221).standard_normal((_PROBES, dense.shape[0]))
            u = w @ dense
            if leading is not None:  # a switched step: C reads the pressure block only
                u = np.hstack([u, np.zeros((_PROBES, leading - u.shape[1]))])
            if bordered:  # a bordered step: eta moves the whole film
                u = np.hstack([u, C.tail(w)[:, None]])
            self._probe = (w, u, np.linalg.norm(w, axis=1))
        # the probes are formed once: C is fixed for a solver's life (its recycled C z are too)
        w, u, wn = self._probe
        err = np.abs(w @ Cx - u @ x) / wn  # ~ |e| / sqrt(elements) per probe
        scale = float(np.linalg.norm(Cx)) / math.sqrt(dense.shape[0])
        return bool(np.all(err <= _TRACK_RTOL * scale))

    def _remember(self, x, Cx, gen, dirs):
        """Keep the newest solutions and preconditioned directions (with C z) for recycling,
        and the generations of tracking behind each solution's ``C x``."""
        if self.recycle <= 0:
            return
        nsol = min(4, self.recycle)
        self.solutions = ([(x, Cx)] + self.solutions)[:nsol]
        self._solution_ages = ([gen] + self._solution_ages)[:nsol]
        self.directions = (dirs + self.directions)[: max(0, self.recycle - len(self.solutions))]
