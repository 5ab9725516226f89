"""docs/figures/synth-samples.png: samples of a `dqhand.synth` data set as a user reads them
back (`synth.read`, `synth.images`): each depth map shaded over its masks (the hand lilac, a
held ball amber), the 2D keypoints and MediaPipe's skeleton drawn on, visible keypoints
filled, hidden ones hollow.

    python tools/synth_figure.py OUT.png   (makes 12 samples, half holding a ball, no Ray)
"""

import sys
import tempfile

import numpy as np
from PIL import Image, ImageDraw

from dqhand import synth

# MediaPipe Hands' bones: the wrist to each finger's base, then along each finger.
BONES = [(0, 1), (0, 5), (0, 9), (0, 13), (0, 17)] + [(f + i, f + i + 1) for f in (1, 5, 9, 13, 17) for i in range(3)]
FINGER_COLOURS = [(230, 159, 0), (86, 180, 233), (0, 158, 115), (240, 228, 66), (204, 121, 167)]


def colour(keypoint):
    return (255, 255, 255) if keypoint == 0 else FINGER_COLOURS[(keypoint - 1) // 4]


def tile(hand, ball, depth, pixels, visible):
    """One sample: near surfaces light, far dark, the background black."""
    seen = hand | ball
    shade = np.zeros(depth.shape)
    if seen.any():
        near, far = depth[seen].min(), depth[seen].max()
        shade[seen] = 0.35 + 0.65 * (far - depth[seen]) / max(far - near, 1e-6)
    tint = np.where(ball[..., None], [1.0, 0.7, 0.3], [0.85, 0.8, 1.0])
    image = Image.fromarray((shade[..., None] * tint * 255).astype(np.uint8)).resize((2 * depth.shape[1], 2 * depth.shape[0]), Image.NEAREST)
    draw = ImageDraw.Draw(image)
    points = 2 * pixels + 1  # pixel (i, j), centred on image point (i, j), is 2i..2i+2 scaled
    for a, b in BONES:
        draw.line([tuple(points[a]), tuple(points[b])], fill=colour(b), width=2)
    for k, (x, y) in enumerate(points):
        box = [x - 4, y - 4, x + 4, y + 4]
        draw.ellipse(box, fill=colour(k) if visible[k] else None, outline=colour(k), width=2)
    return image


def main(path):
    with tempfile.TemporaryDirectory() as folder:
        synth.synth(12, f"{folder}/set", seed=2026, image_size=192, shard_size=3, ball_share=0.5, use_ray=False)
        table = synth.read(f"{folder}/set")
    hands, balls, depth = synth.images(table)
    pixels = table["keypoints_2d"].combine_chunks().flatten().to_numpy().reshape(-1, 21, 2)
    visible = table["visible"].combine_chunks().flatten().to_numpy(zero_copy_only=False).reshape(-1, 21)
    tiles = [tile(hands[i], balls[i], depth[i], pixels[i], visible[i]) for i in range(table.num_rows)]
    side = tiles[0].width
    sheet = Image.new("RGB", (6 * side + 5 * 4, 2 * side + 4), (255, 255, 255))
    for i, t in enumerate(tiles):
        sheet.paste(t, ((i % 6) * (side + 4), (i // 6) * (side + 4)))
    sheet.save(path, optimize=True)


if __name__ == "__main__":
    main(sys.argv[1])
