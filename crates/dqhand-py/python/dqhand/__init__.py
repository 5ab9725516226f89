"""dqhand: a realistic virtual hand (anatomical skeleton, dual quaternion skinning) as NumPy arrays.

SI units throughout (metres, radians), the batch dimension first::

    import numpy as np
    import dqhand

    hand = dqhand.Hand.builtin()                     # the built-in right hand, 23 joint angles
    angles = np.zeros((4, len(hand.dof_names)))      # four poses (radians)
    angles[:, hand.dof_names.index("index-finger-phalanx-intermediate.flex")] = np.radians(90)
    vertices = hand.skin(angles)                     # (4, V, 3), dual quaternion blending
    joints = hand.joints(angles)                     # (4, 25, 3), WebXR joint order
"""

from ._dqhand import MEDIAPIPE_KEYPOINTS, WEBXR_JOINTS, Hand, render_depth
from ._dqhand import gesture_names, read_recording, write_recording

__all__ = ["Hand", "WEBXR_JOINTS", "MEDIAPIPE_KEYPOINTS", "render_depth", "gesture_names", "read_recording", "write_recording"]
