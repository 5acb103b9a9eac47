"""See what a skeletal animation really does to every bone: the polar decomposition of every bone's matrix over
time, shear and scale inheritance, why a bone shears and the cheapest fix, and bakes every engine plays."""

from os import PathLike
from typing import Any, Dict, List, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

Path = Union[str, "PathLike[str]"]
#: A clip by name or index.
ClipChoice = Union[str, int]
#: One mode for every bone ("declared", "full", "segment-compensate", …), or bone names (or indices) to modes.
ModesChoice = Union[str, Mapping[Union[str, int], str]]
#: A report as the command line's JSON: dicts, lists, strings, numbers, None.
Json = Dict[str, Any]

#: The version of the wheel, which is the command line's (`bonescope --version`).
__version__: str

class Error(Exception):
    """What bonescope cannot read or do: one line naming the file and the place, as the command line says it."""

class Bone:
    """One bone (a node of the file)."""

    index: int
    name: str
    parent: Optional[int]
    #: The mode the file declares ("full" where the format has none).
    mode: str
    #: "joint", "end site", "mesh", "camera", "light" or "helper".
    role: str

class Clip:
    """One animation of the file."""

    index: int
    name: Optional[str]
    #: Where it starts on its file's clock, seconds (a glb's first key, a USD stage's start time code over its
    #: rate, an FBX take's stored start).
    start: float
    #: How long it plays, seconds.
    duration: float
    #: Frames per second: the file's, or the one its key times show.
    frame_rate: float
    #: Every key time, in seconds, sorted.
    key_times: List[float]

class Mesh:
    """One mesh of the file."""

    name: str
    vertices: int
    #: The bone it hangs from.
    bone: int
    skinned: bool
    morph_targets: int

class Evaluation:
    """Every bone of a clip at every time asked for, indexed [time, bone, ...] (float64 unless said): matrices
    m[t, b, row, column] with column vectors (the translation in m[t, b, :3, 3]), quaternions [x, y, z, w]. The model
    matrix's parts are Shoemake's M = T·F·R·U·K·Uᵀ, as `bonescope inspect` prints them."""

    #: (T,): the times, in seconds.
    times: npt.NDArray[np.float64]
    #: The bones' names, in index order.
    bones: List[str]
    #: (T, B, 4, 4): each bone's local matrix (relative to its parent, as its mode makes it).
    local: npt.NDArray[np.float64]
    #: (T, B, 4, 4): each bone's model matrix (the whole chain, in metres, Y up).
    model: npt.NDArray[np.float64]
    #: (T, B, 3): T.
    translation: npt.NDArray[np.float64]
    #: (T, B, 4): the essential rotation R.
    rotation: npt.NDArray[np.float64]
    #: (T, B, 4): the stretch rotation U, the frame the scale factors apply in.
    stretch: npt.NDArray[np.float64]
    #: (T, B, 3): the scale factors K (as the file's author set them).
    scale: npt.NDArray[np.float64]
    #: (T, B): F, 1 or -1 (mirrored).
    sign: npt.NDArray[np.float64]
    #: (T, B): the largest deviation from 90° between two columns of the model matrix, in degrees, at each time: its
    #: maximum over the times is the sampled worst, which `Rig.scan` refines between the samples (`worst_shear_deg`,
    #: as the command line reports it).
    shear_deg: npt.NDArray[np.float64]
    #: (T, B): the angle of U, in degrees.
    stretch_deg: npt.NDArray[np.float64]
    #: (T, B): stretched (scale along axes that shear) under the tolerances.
    stretched: npt.NDArray[np.bool_]

class Rig:
    """A loaded file: its skeleton, clips and meshes, and what can be asked of it."""

    @property
    def file(self) -> str:
        """The path the rig was loaded from."""
    @property
    def bones(self) -> List[Bone]:
        """Every bone, parents before children."""
    @property
    def clips(self) -> List[Clip]:
        """Every animation."""
    @property
    def meshes(self) -> List[Mesh]:
        """Every mesh."""
    @property
    def notes(self) -> List[str]:
        """What the importer says about the file: units and axes, how animation was read, what was skipped."""
    @property
    def unit(self) -> Optional[str]:
        """The unit the file's lengths are in, as the reports write it ("metres" for glTF, FBX and USD), or None (BVH)."""
    def evaluate(
        self,
        clip: Optional[ClipChoice] = None,
        times: Optional[Sequence[float]] = None,
        *,
        modes: Optional[ModesChoice] = None,
        layers: Optional[Json] = None,
        rate: float = 60.0,
        min_anisotropy: Optional[float] = None,
        min_stretch_deg: Optional[float] = None,
        min_shear_deg: Optional[float] = None,
        min_non_uniform: Optional[float] = None,
    ) -> Evaluation:
        """Every bone at `times` (seconds; default every key time plus `rate` per second, as `scan` samples).
        `layers` are the runtime techniques as `bonescope inspect --format json` echoes them."""
    def scan(
        self,
        clip: Optional[ClipChoice] = None,
        *,
        modes: Optional[ModesChoice] = None,
        layers: Optional[Json] = None,
        rate: float = 60.0,
        explain: bool = False,
        min_anisotropy: Optional[float] = None,
        min_stretch_deg: Optional[float] = None,
        min_shear_deg: Optional[float] = None,
        min_non_uniform: Optional[float] = None,
    ) -> Json:
        """Whole clips (default every one) as `bonescope scan FILE --format json` reports this file; Ctrl+C stops it."""
    def explain(
        self,
        bone: Optional[Union[str, int, Sequence[Union[str, int]]]] = None,
        *,
        time: Optional[float] = None,
        clip: Optional[ClipChoice] = None,
        modes: Optional[ModesChoice] = None,
        layers: Optional[Json] = None,
        rate: float = 60.0,
        min_anisotropy: Optional[float] = None,
        min_stretch_deg: Optional[float] = None,
        min_shear_deg: Optional[float] = None,
        min_non_uniform: Optional[float] = None,
    ) -> Json:
        """Why bones shear and every fix ranked, as `bonescope explain FILE --format json` says it."""

def load(path: Path, *, max_memory: Optional[Union[int, str]] = None) -> Rig:
    """Loads an animation file (glTF, FBX, BVH, USD; recognised by content). `max_memory`: bytes or "8GiB"."""

def diff(
    a: Path,
    b: Path,
    *,
    anim_a: Optional[ClipChoice] = None,
    anim_b: Optional[ClipChoice] = None,
    inherit_a: str = "declared",
    inherit_b: str = "declared",
    map: Optional[Mapping[str, str]] = None,
    interp: Optional[str] = None,
    rate: float = 60.0,
    unit_a: Optional[str] = None,
    unit_b: Optional[str] = None,
    up_a: Optional[str] = None,
    up_b: Optional[str] = None,
    align: Optional[Union[str, float]] = None,
) -> Json:
    """Two files compared over time, bone by bone and vertex by vertex, as `bonescope diff A B --format json`.

    `align`: `"clocks"` compares equal times of both files' clocks, `"start"` plays B from A's start, a number of
    seconds plays B that much later (``--align``)."""

def bake(
    path: Path,
    out: Path,
    engine: str = "generic",
    *,
    strategy: Optional[str] = None,
    tolerance: float = 1e-4,
    clip: Optional[ClipChoice] = None,
    modes: Optional[ModesChoice] = None,
    layers: Optional[Json] = None,
) -> Json:
    """Bakes `path` into a glTF binary at `out` that `engine` plays as the source evaluates; the measured report."""
