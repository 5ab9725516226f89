"""Type stubs of dqhand's native module."""

from os import PathLike
from typing import Any, Dict, List, Literal, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

WEBXR_JOINTS: List[str]
MEDIAPIPE_KEYPOINTS: List[str]

_Angles = npt.ArrayLike  # (B, D) numbers, radians
_Wrist = Optional[npt.ArrayLike]  # (B, 4, 4) rigid transforms, or None for the rest wrist

class Hand:
    """A skinned hand mesh on a skeleton with WebXR hand joints, posed by joint angles."""

    @staticmethod
    def builtin(
        length: float = 0.19,
        breadth: float = 0.085,
        side: Literal["right", "left"] = "right",
        vertices: Optional[int] = None,
        model: Literal["full", "paper"] = "full",
    ) -> "Hand": ...
    @staticmethod
    def load(path: Union[str, PathLike[str]], model: Literal["full", "paper"] = "full") -> "Hand": ...
    @property
    def faces(self) -> npt.NDArray[np.uint32]: ...
    @property
    def rest_vertices(self) -> npt.NDArray[np.float32]: ...
    @property
    def joint_names(self) -> List[str]: ...
    @property
    def dof_names(self) -> List[str]: ...
    @property
    def limits(self) -> npt.NDArray[np.float32]: ...
    @property
    def influences(self) -> Tuple[npt.NDArray[np.uint32], npt.NDArray[np.float32]]: ...
    @property
    def centres_of_rotation(self) -> npt.NDArray[np.float32]: ...
    @overload
    def skin(
        self, angles: _Angles, wrist: _Wrist = None, method: Literal["dqb", "qb", "lb", "cor"] = "dqb", *, normals: Literal[False] = False, limits: bool = True, contact_pass: bool = False
    ) -> npt.NDArray[np.float32]: ...
    @overload
    def skin(
        self, angles: _Angles, wrist: _Wrist = None, method: Literal["dqb", "qb", "lb", "cor"] = "dqb", *, normals: Literal[True], limits: bool = True, contact_pass: bool = False
    ) -> Tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]: ...
    @overload
    def skin(
        self, angles: _Angles, wrist: _Wrist = None, method: Literal["dqb", "qb", "lb", "cor"] = "dqb", *, normals: bool, limits: bool = True, contact_pass: bool = False
    ) -> Union[npt.NDArray[np.float32], Tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]]: ...
    def joints(self, angles: _Angles, wrist: _Wrist = None, limits: bool = True) -> npt.NDArray[np.float32]: ...
    def keypoints(self, angles: _Angles, wrist: _Wrist = None, limits: bool = True) -> npt.NDArray[np.float32]: ...
    def skinning_transforms(self, angles: _Angles, wrist: _Wrist = None, limits: bool = True) -> npt.NDArray[np.float32]: ...
    def close_on_ball(
        self, angles: _Angles, centres: npt.ArrayLike, radii: npt.ArrayLike, *, limits: bool = True
    ) -> Tuple[npt.NDArray[np.float32], npt.NDArray[np.bool_]]:
        """The hand (wrist at rest) closing from open towards ``angles`` (B, D) on balls at ``centres`` (B, 3) of ``radii`` (B,), m.

        Returns the rendered angles (B, D) of the engine's contact-constrained hand (each finger
        stops where its collision proxies touch the ball) and (B,) whether the open hand was
        clear of the ball; where it was not, a finger touching it open does not close on it.
        """
    def gesture_poses(self) -> Dict[str, npt.NDArray[np.float32]]:
        """The gesture library's shapes as this hand's angles: name -> (D,) radians, the wrist at rest."""
    def fit(
        self, points: npt.ArrayLike, kind: Literal["mediapipe", "webxr"] = "mediapipe", *, side: Optional[Literal["right", "left"]] = None
    ) -> Tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]:
        """Retarget tracked points of any hand to this hand: (angles (B, D) radians, wrists (B, 4, 4)).

        ``points`` (B, 21, 3) MediaPipe landmarks (``kind="mediapipe"``) or (B, 25, 3) WebXR
        joints (``kind="webxr"``), metres; ``side`` the tracked hand's (default: this hand's; the
        other side is mirrored onto it). The engine's retargeter (webcam and WebXR input): bone
        directions only, each angle within its range, thumb-to-fingertip contacts kept.
        """
    def recognize_recording(
        self,
        path: Union[str, PathLike[str]],
        *,
        side: Literal["right", "left"] = "right",
        gestures: Optional[Union[str, PathLike[str]]] = None,
        config: Optional[Union[str, PathLike[str]]] = None,
        glove_table: str = "5dt-14",
    ) -> List[Tuple[float, Literal["start", "end"], str]]:
        """Gesture events (t, "start" | "end", gesture) of a JSON lines recording, as ``dqhand replay --gestures`` prints them.

        ``side`` for records that do not say; ``gestures`` a definitions file (else the built-in
        set); ``config`` an input configuration file; ``glove_table`` the glove of glove records.
        A malformed line raises ValueError naming the file and line.
        """
    def recognize(
        self,
        times: npt.ArrayLike,
        angles: Optional[npt.ArrayLike] = None,
        wrist: _Wrist = None,
        *,
        landmarks: Optional[npt.ArrayLike] = None,
        joints: Optional[npt.ArrayLike] = None,
        side: Optional[Union[str, Sequence[str]]] = None,
        gestures: Optional[Union[str, PathLike[str]]] = None,
        config: Optional[Union[str, PathLike[str]]] = None,
        limits: bool = True,
    ) -> List[Tuple[float, Literal["start", "end"], str]]:
        """Gesture events (t, "start" | "end", gesture) of a sequence at ``times`` (T,) seconds.

        Exactly one of ``landmarks`` (T, 21, 3) or ``joints`` (T, 25, 3), metres, played through
        the gesture loop as a recording of them would be (filtered, retargeted; ``side`` one side
        or one per record, default this hand's), or this hand's ``angles`` (T, D) radians with
        ``wrist`` (T, 4, 4) or None given straight to the recogniser.
        """
    def realism(
        self,
        angles: _Angles,
        wrist: _Wrist = None,
        method: Literal["dqb", "qb", "lb", "cor"] = "dqb",
        *,
        joint: str = "index-finger-phalanx-intermediate",
        next: Optional[str] = None,
        self_intersections: bool = False,
        limits: bool = True,
    ) -> Dict[str, npt.NDArray[Union[np.float32, np.uint64]]]:
        """The realism measures of ``dqhand metrics`` for each pose under ``method``: name -> (B,).

        ``volume`` against rest (NaN for an open mesh); around ``joint`` (its region:
        ``joint_region``), ``min_distance`` / ``max_distance`` skin-to-bone against bind (< 1
        collapse, > 1 bulge), ``section_radius`` (< 1: candy wrapper), ``distortion_mean`` /
        ``distortion_max`` of edge lengths; with ``self_intersections`` the crossing triangle pairs.
        """
    def joint_region(self, joint: str, next: Optional[str] = None) -> Dict[str, Union[npt.NDArray[np.uint32], float]]:
        """The skin ``realism`` measures around ``joint``: ``vertices``, ``joints`` (parent, joint, next), ``radius``, ``min_radius`` (m, bind pose)."""
    def realism_report(self) -> Dict[str, Any]:
        """``dqhand metrics --json`` of this hand: LB, QB, DQB and CoR on the sweeps, self-intersections, headline numbers."""
    def export_gltf(self, path: Union[str, PathLike[str]]) -> None:
        """Write this hand as the rigged, skinned GLB ``dqhand hand`` writes (a ``.glb`` name); ``Hand.load`` reads it back."""
    def export_posed(
        self,
        path: Union[str, PathLike[str]],
        angles: npt.ArrayLike,
        wrist: Optional[npt.ArrayLike] = None,
        method: Literal["dqb", "qb", "lb", "cor"] = "dqb",
        *,
        limits: bool = True,
    ) -> None:
        """Write one posed mesh with normals as ``dqhand skin`` does (.ply, .obj or static .glb): ``angles`` (D,), ``wrist`` (4, 4) or None."""

def read_recording(
    path: Union[str, PathLike[str]], *, side: Literal["right", "left"] = "right", glove_table: str = "5dt-14"
) -> Dict[str, npt.NDArray[Any]]:
    """A JSON lines recording (as ``dqhand replay`` reads) as arrays, one row per record.

    ``t`` (T,) s and ``side`` (T,) always; where any record has them ``arrival`` (T,),
    ``joints`` (T, 25, 3) with ``joint_orientations`` (T, 25, 4) x y z w and ``joint_radii``
    (T, 25), ``landmarks`` (T, 21, 3), ``glove`` (T, S), ``tracker_position`` (T, 3) and
    ``tracker_orientation`` (T, 4); NaN where a record lacks it. A malformed line raises
    ValueError naming the file and line.
    """

def write_recording(
    path: Union[str, PathLike[str]],
    t: npt.ArrayLike,
    *,
    joints: Optional[npt.ArrayLike] = None,
    joint_orientations: Optional[npt.ArrayLike] = None,
    joint_radii: Optional[npt.ArrayLike] = None,
    landmarks: Optional[npt.ArrayLike] = None,
    glove: Optional[npt.ArrayLike] = None,
    tracker_position: Optional[npt.ArrayLike] = None,
    tracker_orientation: Optional[npt.ArrayLike] = None,
    side: Optional[Union[str, Sequence[str]]] = None,
    arrival: Optional[npt.ArrayLike] = None,
    glove_table: str = "5dt-14",
) -> None:
    """Write a recording ``dqhand replay`` and ``read_recording`` read, one record per row of ``t``.

    At most one of ``joints``, ``landmarks``, ``glove`` per call, and/or the tracker; ``side``
    one side (default "right") or one per record. Each record is read back by the engine's
    reader before the file is written; its refusal is a ValueError naming the record.
    """

def gesture_names(gestures: Optional[Union[str, PathLike[str]]] = None) -> List[str]:
    """The gestures the recogniser reports: the built-in set, or that of a definitions file."""

def render_depth(
    vertices: npt.ArrayLike, faces: npt.ArrayLike, intrinsics: npt.ArrayLike, extrinsics: npt.ArrayLike, width: int, height: int
) -> npt.NDArray[np.float32]:
    """Depth maps (B, height, width), m, 0 off the mesh, of meshes seen by pinhole cameras.

    ``vertices`` (B, V, 3) m, ``faces`` (F, 3) vertex indices (either winding), ``intrinsics``
    (B, 3, 3) camera matrices K in pixels, ``extrinsics`` (B, 4, 4) world-to-camera transforms;
    OpenCV's axes (x right, y down, z forward), pixel (i, j) centred on image point (i, j).
    ``depth > 0`` is the mask.
    """
