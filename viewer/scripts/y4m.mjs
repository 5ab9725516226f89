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

/**
 * A video of both of a user's hands from one of the right hand (`C420jpeg`, even width): each
 * frame beside its mirror image, twice as wide. A camera facing the user sees their right hand
 * on its left, so the frame stays on the left (its number stays readable in the top-left
 * corner) and the mirrored one, their left hand, goes on the right. Returns the new size.
 * @param {Buffer} y4m - the right hand's video, a whole YUV4MPEG2 file
 * @returns {{ y4m: Buffer, size: [number, number] }}
 */
export function besideItsMirror(y4m) {
  const headerEnd = y4m.indexOf(0x0a);
  const header = y4m.subarray(0, headerEnd).toString('latin1');
  const w = Number(/ W(\d+)/.exec(header)?.[1]);
  const h = Number(/ H(\d+)/.exec(header)?.[1]);
  if (!header.startsWith('YUV4MPEG2') || !header.includes('C420jpeg') || !(w > 0 && h > 0) || w % 2 || h % 2) throw new Error(`not a 4:2:0 YUV4MPEG2 video of even size: ${header}`);
  const planes = [[w, h], [w / 2, h / 2], [w / 2, h / 2]];
  const frameBytes = (w * h * 3) / 2;
  const out = [Buffer.from(header.replace(` W${w}`, ` W${2 * w}`) + '\n', 'latin1')];
  let at = headerEnd + 1;
  while (at < y4m.length) {
    const line = y4m.indexOf(0x0a, at);
    if (y4m.subarray(at, line).toString('latin1') !== 'FRAME') throw new Error(`no FRAME at byte ${at}`);
    out.push(Buffer.from('FRAME\n', 'latin1'));
    let from = line + 1;
    if (from + frameBytes > y4m.length) throw new Error(`a frame cut short at byte ${from}`);
    for (const [pw, ph] of planes) {
      const plane = Buffer.alloc(2 * pw * ph);
      for (let y = 0; y < ph; y++) {
        const row = y4m.subarray(from + y * pw, from + (y + 1) * pw);
        row.copy(plane, 2 * pw * y);
        for (let x = 0; x < pw; x++) plane[2 * pw * y + 2 * pw - 1 - x] = row[x];
      }
      out.push(plane);
      from += pw * ph;
    }
    at = from;
  }
  return { y4m: Buffer.concat(out), size: [2 * w, h] };
}
