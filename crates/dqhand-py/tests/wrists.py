"""Random rigid wrists, shared by the test files."""

import numpy as np


def random_wrists(count, seed):
    """Rigid transforms: turned up to 180° about a random axis, moved up to half a metre."""
    rng = np.random.default_rng(seed)
    out = np.zeros((count, 4, 4))
    for b in range(count):
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        angle = rng.uniform(0, np.pi)
        k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        out[b, :3, :3] = np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k
        out[b, :3, 3] = rng.uniform(-0.5, 0.5, size=3)
        out[b, 3, 3] = 1
    return out
