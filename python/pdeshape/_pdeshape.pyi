"""Type stubs of the compiled extension (see the docstrings for the array layouts)."""

from os import PathLike
from typing import Any, Literal, Mapping, TypedDict

import numpy as np
import numpy.typing as npt

F64 = npt.NDArray[np.float64]
F32 = npt.NDArray[np.float32]
U32 = npt.NDArray[np.uint32]
#: A number, a list or an array of any shape (broadcast against the other parameter).
ArrayLike = npt.ArrayLike

class DesignError(ValueError):
    """A design that cannot be read, solved or written; the message is the CLI's."""

class Tessellation(TypedDict):
    vertices: F64  # (n, 3), the CSV rows: patch-major, then u-major (i outer, j inner)
    normals: F64  # (n, 3) unit normals
    uv: F64  # (n, 2) parameter values (u_i, v_j)
    patch: U32  # (n,) 0-based surface index
    faces: U32  # (m, 3) two triangles per quad, counter-clockwise about the normal
    shape: npt.NDArray[np.uint64]  # (k, 2) nu, nv of each surface

class Mesh(TypedDict):
    vertices: F32  # (n, 3) welded vertices, as the OBJ/STL/PLY/glTF files store them
    normals: F32  # (n, 3)
    uv: F32  # (n, 2), or (0, 2) when absent
    faces: U32  # (m, 3)
    parts: list[tuple[str, int, int]]  # (surface name, first face, end face)

class Partials(TypedDict):
    x: F64
    xu: F64
    xv: F64
    xuu: F64
    xuv: F64
    xvv: F64

class Curvatures(TypedDict):
    gauss: F64
    mean: F64
    k1: F64
    k2: F64
    normal: F64

class Frames(TypedDict):
    step: npt.NDArray[np.uint64]  # (F,) the levels n of the frames
    t: F64  # (F,) t_n
    nodes: F64  # (F, J+1, dim) C(u_j, t_n): the rows of `pdeshape curve --frames`

class DynamicCurve(TypedDict, total=False):
    kind: str  # "run" (the scheme) or "interpolate" (the interpolating curve)
    dim: int  # 1 to 3 coordinates
    u: F64  # (J+1,) u_j = j/J
    nodes: F64  # (J+1, dim) the final curve: the rows of `pdeshape curve -o`
    frames: Frames
    bending_energy: float
    t_end: float  # run only
    steps: int
    points: F64  # interpolate only: (P, dim) the data points
    params: F64  # (P,) the nodes' u of the points
    distances: F64  # (P,) |p_i - C(u_i)|
    updates: int

class ConstraintValue(TypedDict):
    expr: str
    value: float  # the formula's value
    equal: float | None
    min: float | None
    max: float | None
    weight: float

class ProblemValue(TypedDict):
    x: dict[str, float]  # every [optimize] parameter's value
    value: float  # objective + penalty
    objective: float
    penalty: float
    feasible: bool
    measures: dict[str, float]  # the formulas' variables (area, volume, mean, …, nu, c0, …)
    constraints: list[ConstraintValue]

class ConstraintGradient(TypedDict):
    expr: str
    value: float
    gradient: F64  # (k,)
    equal: float | None
    min: float | None
    max: float | None

class Gradient(TypedDict, total=False):
    names: list[str]  # the k parameters
    x: dict[str, float]
    measures: dict[str, float]  # area, volume, mean, mean_sq, gauss, bending, willmore, …
    d_measures: dict[str, F64]  # (k,) ∂measure/∂parameter
    errors: dict[str, F64]  # (k,) estimated absolute error of each derivative
    methods: list[str]  # "linear", "rotation" (exact up to rounding) or "richardson"
    exact: list[bool]
    solves: int  # design solves (the steps of the parameters not in the batch)
    tangent_solves: int  # batched tangent solves (one block of right-hand sides each)
    batch: int  # parameters differentiated by the batched tangent solve
    # with the [optimize] problem (names None):
    objective: float
    d_objective: F64
    penalty: float
    d_penalty: F64
    value: float
    d_value: F64
    constraints: list[ConstraintGradient]

class StartResult(TypedDict):
    x: dict[str, float]  # the start point
    best: float  # the best value (objective + penalty) this start evaluated
    status: str  # how the start ended: "first_order", or SLSQP's "success", "ftol_reached", "xtol_reached" (converged); "max_evaluations", "roundoff_limited", … (not)
    converged: bool  # ended on a convergence test
    evaluations: int  # gradient evaluations of this start

class Kkt(TypedDict):
    # first-order conditions at the result in the scaled variables (parameters in [0, 1], the
    # objective over its value at the first point, constraints c <= 0 over max(|bound|, 1))
    stationarity: float  # projected gradient of the Lagrangian (0 at a first-order optimum)
    dual_infeasibility: float  # max(-multiplier, 0) over the active constraints
    primal_infeasibility: float  # largest scaled constraint violation
    active_constraints: int
    active_bounds: int

class GradientSearch(TypedDict):
    evaluations: int  # gradient evaluations, all starts
    solves: int
    converged: bool  # the start that found the result converged
    best_start: int
    starts: list[StartResult]
    kkt: Kkt

class OptimizeResult(TypedDict):
    x: dict[str, float]  # the best parameter values
    value: float  # objective + penalty
    objective: float
    penalty: float
    feasible: bool
    method: str
    evaluations: int  # annealing and polish evaluations, or gradient evaluations
    solves: int  # design solves
    tangent_solves: int  # batched tangent solves of the gradients (not in solves)
    start_value: float  # objective + penalty at the initial values
    measures: dict[str, float]  # the formulas' variables at the result (shell ones where set up)
    gradient: GradientSearch | None  # None for annealing; the hybrid's gradient stage

#: An equality constraint holds within this tolerance relative to max(|target|, 1).
EQUALITY_TOLERANCE: float

class Design:
    @staticmethod
    def load(path: str | PathLike[str]) -> Design: ...
    @staticmethod
    def from_toml(text: str, name: str = "<string>") -> Design: ...
    @staticmethod
    def from_json(text: str, name: str = "<dict>") -> Design: ...
    @staticmethod
    def from_dict(d: Mapping[str, Any], name: str = "<dict>") -> Design: ...
    @property
    def text(self) -> str: ...
    @property
    def file(self) -> str: ...
    @property
    def title(self) -> str | None: ...
    @property
    def units(self) -> str | None: ...
    @property
    def curves(self) -> list[str]: ...
    @property
    def patches(self) -> list[str]: ...
    @property
    def is_solved(self) -> bool: ...
    def parameters(self) -> list[dict[str, Any]]: ...
    def parameter_names(self) -> list[str]: ...
    def params(self) -> dict[str, float]: ...
    def with_params(self, values: Mapping[str, float]) -> Design: ...
    def solve(self) -> None: ...
    def grid_size(self, nu: int | None = None, nv: int | None = None) -> tuple[int, int]: ...
    def tessellate(self, nu: int | None = None, nv: int | None = None) -> Tessellation: ...
    def mesh(
        self, nu: int | None = None, nv: int | None = None, separate_patches: bool = False
    ) -> Mesh: ...
    def evaluate(
        self, u: ArrayLike, v: ArrayLike, patch: int | str | None = None, clamp: bool = False
    ) -> Partials: ...
    def curvature(
        self, u: ArrayLike, v: ArrayLike, patch: int | str | None = None, clamp: bool = False
    ) -> Curvatures: ...
    def spine(
        self, u: ArrayLike, patch: int | str | None = None, order: int = 0, clamp: bool = False
    ) -> F64: ...
    def check(self) -> dict[str, Any]: ...
    def analysis(
        self, tolerance: float | None = None, quadrature: tuple[int, int] | None = None
    ) -> dict[str, Any]: ...
    def write(
        self,
        path: str | PathLike[str],
        nu: int | None = None,
        nv: int | None = None,
        format: str | None = None,
        scale: float = 1.0,
        up: str | None = None,
        separate_patches: bool = False,
        tolerance: float | None = None,
        units: str | None = None,
        timestamp: int | None = None,
    ) -> None: ...
    @property
    def has_dynamic(self) -> bool: ...
    def dynamic(self, frames: bool = True) -> DynamicCurve: ...
    def optimize(
        self,
        seed: int | None = None,
        evaluations: int | None = None,
        chains: int | None = None,
        polish: int | None = None,
        method: Literal["anneal", "gradient", "hybrid"] = "anneal",
        starts: int | None = None,
    ) -> OptimizeResult: ...
    def evaluate_problem(self, values: Mapping[str, float] | None = None) -> ProblemValue: ...
    def gradient(
        self, names: list[str] | None = None, quadrature: tuple[int, int] | None = None
    ) -> Gradient: ...
    def to_trimesh(
        self,
        nu: int | None = None,
        nv: int | None = None,
        separate_patches: bool = False,
        welded: bool = True,
    ) -> Any: ...
    def to_pyvista(
        self,
        nu: int | None = None,
        nv: int | None = None,
        separate_patches: bool = False,
        welded: bool = True,
    ) -> Any: ...

def version() -> str: ...
def fill_mesh(
    data: bytes | None = None,
    name: str = "<mesh>",
    positions: list[list[float]] | None = None,
    triangles: list[list[int]] | None = None,
    continuity: str = "g1",
    largest: int | None = None,
    max_boundary: int | None = None,
    grading: float = 0.1,
) -> dict[str, Any]: ...
def fit_mesh(
    data: bytes,
    name: str,
    tolerance: float | None = None,
    sections: int | None = None,
    mode: str = "auto",
    best_effort: bool = False,
) -> tuple[Design, dict[str, Any]]: ...
