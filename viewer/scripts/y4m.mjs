// The webcam videos' frames (webcam-video.mjs, generic-hand-video.mjs): a page's canvas read
// back, and RGBA to the planar 4:2:0 of a YUV4MPEG2 `C420jpeg` file.

/** In the page: the canvas scaled to `size`, mirrored left to right if asked, as base64 RGBA. */
export function readCanvas([w, h, mirror]) {
  const c = document.getElementById('view');
  const g = Object.assign(document.createElement('canvas'), { width: w, height: h }).getContext('2d');
  if (mirror) g.setTransform(-1, 0, 0, 1, w, 0);
  g.drawImage(c, 0, 0, w, h);
  const bytes = g.getImageData(0, 0, w, h).data;
  let s = '';
  for (let i = 0; i < bytes.length; i += 0x8000) s += String.fromCharCode(...bytes.subarray(i, i + 0x8000));
  return btoa(s);
}

/** RGBA to planar Y, U, V at half resolution in both directions (BT.601 full range, JPEG's). */
export function toI420(rgba, w, h) {
  const out = Buffer.alloc((w * h * 3) / 2);
  const [cw, ch] = [w / 2, h / 2];
  for (let y = 0; y < h; y++) {
    for (let x = 0; x < w; x++) {
      const i = 4 * (y * w + x);
      out[y * w + x] = Math.round(0.299 * rgba[i] + 0.587 * rgba[i + 1] + 0.114 * rgba[i + 2]);
    }
  }
  for (let y = 0; y < ch; y++) {
    for (let x = 0; x < cw; x++) {
      let [r, g, b] = [0, 0, 0];
      for (const [dx, dy] of [[0, 0], [1, 0], [0, 1], [1, 1]]) {
        const i = 4 * ((2 * y + dy) * w + 2 * x + dx);
        r += rgba[i] / 4;
        g += rgba[i + 1] / 4;
        b += rgba[i + 2] / 4;
      }
      const clamp = (v) => Math.min(255, Math.max(0, Math.round(v)));
      out[w * h + y * cw + x] = clamp(128 - 0.168736 * r - 0.331264 * g + 0.5 * b);
      out[w * h + cw * ch + y * cw + x] = clamp(128 + 0.5 * r - 0.418688 * g - 0.081312 * b);
    }
  }
  return out;
}

/**
 * A frame's number stamped into its top-left corner, `MARKER.bits` blocks of `MARKER.block`
 * pixels, black for 0 and white for 1, most significant first: a time code a page can read
 * off the camera image (blocks this big survive 4:2:0 and scaling).
 */
export const MARKER = { bits: 11, block: [10, 8] };

/** Stamps frame number `k` into `rgba` (`w` pixels wide), in place. */
export function stampFrame(rgba, w, k) {
  const [bw, bh] = MARKER.block;
  for (let b = 0; b < MARKER.bits; b++) {
    const v = (k >> (MARKER.bits - 1 - b)) & 1 ? 255 : 0;
    for (let y = 0; y < bh; y++) for (let x = b * bw; x < (b + 1) * bw; x++) rgba.fill(v, 4 * (y * w + x), 4 * (y * w + x) + 3);
  }
}
