"""Type stubs of the compiled core (rust/python/mod.rs). Use the public API in granrs instead."""

from collections.abc import Callable
from typing import Any, final

__all__ = [
    "DEFAULT_CHORDS",
    "EFFECTS",
    "FORCE_INPUTS",
    "FORCE_OUTPUTS",
    "GEOM_OUTPUTS",
    "GEOM_STATE",
    "MAX_CHORDS",
    "MAX_CONTACTS",
    "MAX_LINKS",
    "PRESETS",
    "RECORDS",
    "RFT3D_COEFFICIENTS",
    "RFT_COEFFICIENTS",
    "RFT_GENERIC",
    "SCENE_FIELDS",
    "SPACE_DEFAULT_NODES",
    "SPACE_GEOM_OUTPUTS",
    "SPACE_MAX_NODES",
    "SPACE_REST_SPEED",
    "SPACE_SERIES",
    "SPACE_SUMMARY",
    "Compiled",
    "MujocoCoupling",
    "RunOutcome",
    "SandGeoms",
    "SpaceScene",
    "__version__",
    "body_linkage",
    "check_term",
    "compile",
    "compile_fields",
    "compiled_scene",
    "element_fields",
    "fast_lanes",
    "leg_segments",
    "max_threads",
    "output_fields",
    "resistance_force",
    "rft3d_alpha",
    "rft_alpha",
    "run",
    "run_scene",
    "scene_fields",
    "space_load",
    "space_run",
    "space_scene",
    "sweep",
    "term_infos",
    "validate",
    "validate_sweep",
    "xi_n",
]
__version__: str
EFFECTS: list[str]
PRESETS: list[str]
RECORDS: list[str]
RFT_COEFFICIENTS: list[str]
RFT_GENERIC: list[float]
SCENE_FIELDS: list[str]
MAX_LINKS: int
MAX_CONTACTS: int
MAX_CHORDS: int
DEFAULT_CHORDS: int

@final
class Compiled:
    """A scene dict converted and validated by the core (from compile())."""

def compile(scene: dict[str, Any]) -> Compiled:
    """Convert and validate a scene dict once."""

def compile_fields(fields: dict[str, Any], names: tuple[str, ...]) -> Compiled:
    """Convert and validate a Scene once, from its ``__dict__`` and its body's field names."""

def compiled_scene(fields: dict[str, Any], core_fields: dict[str, tuple[str, ...]]) -> Compiled:
    """A Scene's compiled scene, cached in its ``__dict__`` (compiled on first use)."""

@final
class RunOutcome:
    """One run's outcome, kept in the core until asked for."""

    status: str
    t_s: float
    depth: float
    run_seconds: float
    h_lambda: float
    unresolved: int
    unresolved_stops: int
    step_error: float
    def to_dict(self) -> dict[str, Any]:
        """Everything, as a dict; once (the outcome moves out). ``impulses``: the
        table-driven joints' impulses, ``(link, t, impulse, energy)`` tuples in time order
        (the link in the engine's order)."""

def run(compiled: Compiled) -> RunOutcome:
    """Run a compiled scene."""

def output_fields() -> list[dict[str, str]]:
    """The one table of a run's output fields (name, part, unit, and what the run computes
    for it beyond its steps), what a scene's ``outputs`` may list."""

def run_scene(fields: dict[str, Any], core_fields: dict[str, tuple[str, ...]]) -> RunOutcome:
    """Run a Scene from its ``__dict__``: ``compiled_scene`` then ``run``."""

def validate(scene: dict[str, Any]) -> None:
    """Validate a scene dict; raise the typed granrs error naming the first bad field."""

def leg_segments(scene: dict[str, Any]) -> list[dict[str, Any]]:
    """The leg's segments (name, mass, length, com, inertia) for a leg scene dict."""

def sweep(
    base: dict[str, Any] | None = None,
    axes: list[tuple[str, list[Any]]] | None = None,
    scenes: list[dict[str, Any] | Compiled] | None = None,
    start: int = 0,
    stop: int | None = None,
    threads: int = 0,
    progress: Callable[[int], None] | None = None,
    lanes: bool = True,
    outputs: list[str] | tuple[str, ...] | None = None,
) -> dict[str, Any]:
    """Run runs start..stop of a batch (the product of axes over base, or a list of scene
    dicts or compiled scenes) on `threads` threads (0, or more than the cores: every core),
    each returning `outputs` (None: the scenes' own); return columns, data (rows x columns),
    failures [(run, message)] and body."""

def validate_sweep(
    base: dict[str, Any] | None = None,
    axes: list[tuple[str, list[Any]]] | None = None,
    scenes: list[dict[str, Any] | Compiled] | None = None,
    threads: int = 0,
    outputs: list[str] | tuple[str, ...] | None = None,
) -> int:
    """Validate every run of a batch without running it; return the number of runs."""

def max_threads() -> int:
    """The most threads a sweep runs on: the machine's cores (the shared pool's size)."""

def fast_lanes() -> bool:
    """Whether a sweep's lanes call glibc's four-lane ``sin``, ``cos`` and ``pow``
    (``GRANRS_FAST_LANES=1``, read once per process, on a CPU with AVX2 where libmvec is
    found): then a lane's row is near ``simulate``'s, not its bits."""

FORCE_INPUTS: list[str]
FORCE_OUTPUTS: list[str]

def resistance_force(
    inputs: list[Any],
    length: float,
    diameter: float,
    rho_g: float,
    g: float,
    effects: list[str],
    sign_model: str,
    smooth_eps: float,
) -> Any:
    """The rod force over n states: nine contiguous float64 arrays (FORCE_INPUTS order) in,
    an n x 10 array (FORCE_OUTPUTS order) out."""

GEOM_STATE: list[str]
GEOM_OUTPUTS: list[str]

@final
class SandGeoms:
    """N geoms (rods, sole boxes) of another engine under contact terms, through the free
    link's right-hand side (granrs.mujoco.Sand)."""

    def __new__(
        cls,
        names: list[str],
        shapes: list[tuple[str, list[float]]],
        forces: list[Any],
        rho_g: float,
        g: float,
        apply_at: str = "tip",
        sign_model: str = "raw",
        smooth_eps: float = 1e-3,
    ) -> SandGeoms: ...
    def __len__(self) -> int: ...
    def evaluate(self, states: Any, out: Any) -> None:
        """Every geom's force: states n x 7 (GEOM_STATE order) in, out n x 18
        (GEOM_OUTPUTS order) written."""

def scene_fields() -> list[dict[str, Any]]:
    """The one table of a scene's fields (name, part, bodies, unit, note, doc)."""

def element_fields() -> list[dict[str, Any]]:
    """The one table of a linkage's element fields (element, name, unit, note, doc)."""

def body_linkage(scene: dict[str, Any], check: bool = False) -> dict[str, Any]:
    """A scene's body as a linkage's plain parts (links, joints, contacts, root) and the
    links' names in the engine's order; ``check`` validates the body's structure."""

def term_infos() -> list[dict[str, Any]]:
    """Every registered force term's description (name, equation, params, ...)."""

def check_term(name: str, params: dict[str, Any]) -> dict[str, float | tuple[float, ...]]:
    """Check one term's name and parameters; every parameter with defaults filled in."""

def rft_alpha(beta: Any, gamma: Any, coefficients: list[float]) -> tuple[Any, Any]:
    """RFT (alpha_x, alpha_z) at equal-length float64 arrays of angles [rad]."""

# Bodies in space (granrs.space).
RFT3D_COEFFICIENTS: list[list[float]]
SPACE_GEOM_OUTPUTS: list[str]
SPACE_REST_SPEED: float

@final
class MujocoCoupling:
    """The sand placed on the bodies of a MuJoCo model (granrs.mujoco.Sand): planar rod and
    sole geoms, or geoms as shapes in space."""

    @staticmethod
    def planar(
        rods: SandGeoms,
        geom: list[int],
        body: list[int],
        root: list[int],
        reach: list[float],
        dofs: list[list[int]],
        nv: int,
        surface: float,
        patch: tuple[float, float],
        stick: bool,
        implicit_damping: list[float],
        rest_speed: float,
    ) -> MujocoCoupling: ...
    @staticmethod
    def space(
        names: list[str],
        shapes: list[dict[str, Any]],
        forces: list[tuple[str, dict[str, Any]]],
        rho_g: float,
        surface: float,
        patch: list[float],
        rest_speed: float,
        quadrature: int,
        geom: list[int],
        body: list[int],
        root: list[int],
        dofs: list[list[int]],
        nv: int,
        implicit_damping: list[float],
    ) -> MujocoCoupling: ...
    def bind(self, *arrays: Any) -> None:
        """Bind one mjData's arrays and the caller's buffers (checked once)."""
    def step(
        self, timestep: float, passive: bool, fresh: bool, hold: bool
    ) -> tuple[float, int, int, float, bool, bool]:
        """One evaluation at the bound arrays; the generalized force into qfrc_passive
        (passive) or qfrc_applied. Returns the largest h_lambda, its geom, the Newton
        iterations, the relative residual, whether the solve converged and whether the step
        fell back to sticking or sliding (planar: 0, 0.0, True, False)."""

SPACE_SUMMARY: list[tuple[str, str, str]]
SPACE_SERIES: list[tuple[str, str, str]]
SPACE_MAX_NODES: int
SPACE_DEFAULT_NODES: int

@final
class SpaceScene:
    def mass_properties(self) -> tuple[float, list[list[float]], float]: ...
    def lowest_offset(self) -> tuple[float, float, float]: ...
    def body_vertices(self) -> list[tuple[float, float, float]] | None: ...

def space_scene(scene: dict[str, Any]) -> SpaceScene: ...
def space_run(scene: SpaceScene) -> dict[str, Any]: ...
def space_load(
    scene: SpaceScene,
    position: Any,
    orientation: Any,
    velocity: Any,
    omega: Any,
    error: bool = True,
) -> dict[str, Any]: ...
def xi_n(rho_c: float, mu: float) -> float: ...
def rft3d_alpha(
    n: tuple[float, float, float], v: tuple[float, float, float], grazing: bool
) -> tuple[float, float, float]: ...
