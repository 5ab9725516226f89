"""Type stubs of dqhand's native module."""

from os import PathLike
from typing import List, Literal, Optional, Tuple, Union, overload

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
    @overload
    def skin(
        self, angles: _Angles, wrist: _Wrist = None, method: Literal["dqb", "qb", "lb"] = "dqb", *, normals: Literal[False] = False, limits: bool = True
    ) -> npt.NDArray[np.float32]: ...
    @overload
    def skin(
        self, angles: _Angles, wrist: _Wrist = None, method: Literal["dqb", "qb", "lb"] = "dqb", *, normals: Literal[True], limits: bool = True
    ) -> Tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]: ...
    @overload
    def skin(
        self, angles: _Angles, wrist: _Wrist = None, method: Literal["dqb", "qb", "lb"] = "dqb", *, normals: bool, limits: bool = True
    ) -> Union[npt.NDArray[np.float32], Tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]]: ...
    def joints(self, angles: _Angles, wrist: _Wrist = None, limits: bool = True) -> npt.NDArray[np.float32]: ...
    def keypoints(self, angles: _Angles, wrist: _Wrist = None, limits: bool = True) -> npt.NDArray[np.float32]: ...
    def skinning_transforms(self, angles: _Angles, wrist: _Wrist = None, limits: bool = True) -> npt.NDArray[np.float32]: ...
