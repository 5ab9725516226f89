// The Camera button: the webcam's frames through MediaPipe Hands in this page, each frame's
// hand sent to the engine as a landmarks record (`landmarks.ts`), and the camera image with the
// landmarks shown small and mirrored in a corner. MediaPipe's script, models and WebAssembly
// are served from the page's own build (dist/mediapipe, copied from the npm package by
// vite.config.ts), loaded on the first press: nothing comes from the network, and no frame
// or landmark leaves the page except to the local engine.

import { chosenHand, handsToSend, landmarkRecord, SideFilter, userSide, type Point, type Vec3 } from '../../packages/dqhand/src/landmarks';
import type { Side } from './protocol';
import type { RecordSink } from './sender';

/** MediaPipe Hands' solution API, as its script defines it on `window` (@mediapipe/hands index.d.ts). */
interface HandsResults {
  multiHandLandmarks?: Point[][];
  multiHandWorldLandmarks?: Point[][];
  multiHandedness?: { index: number; score: number; label: 'Left' | 'Right' }[];
}
interface Hands {
  setOptions(options: { useCpuInference?: boolean; selfieMode?: boolean; maxNumHands?: number; modelComplexity?: 0 | 1; minDetectionConfidence?: number; minTrackingConfidence?: number }): void;
  onResults(listener: (results: HandsResults) => void): void;
  initialize(): Promise<void>;
  send(inputs: { image: HTMLVideoElement }): Promise<void>;
  close(): Promise<void>;
}
declare global {
  interface Window {
    Hands?: new (config: { locateFile: (file: string) => string }) => Hands;
    HAND_CONNECTIONS?: [number, number][];
  }
}

/** Where the build puts MediaPipe's files, relative to the page. */
const MEDIAPIPE_DIR = 'mediapipe/';
/** Weight of the newest sample in the running averages of the statistics. */
const SMOOTHING = 0.1;

/** The camera's statistics, as the test hook and the panel show them. */
export interface WebcamState {
  on: boolean;
  /** Why the camera is off or failed, or what it is doing ('loading', 'running'). */
  status: string;
  /** Frames given to MediaPipe, and those it found a hand in. */
  frames: number;
  detected: number;
  /** Records sent to the engine. */
  sent: number;
  /** The user's hands seen in the latest frame, the one followed first. */
  hands: Side[];
  /** MediaPipe's time per frame (ms, running average) and the rate of frames processed (per s). */
  detectMs: number;
  fps: number;
  /** The camera image's size. */
  width: number;
  height: number;
}

export class Webcam {
  private video: HTMLVideoElement | null = null;
  /** MediaPipe, loading or loaded (one for the page's life: it holds its WebAssembly and models). */
  private hands: Promise<Hands> | null = null;
  /** Starts so far (see `toggle`). */
  private starts = 0;
  private busy = false;
  private lastFrameAt = 0;
  private readonly side = new SideFilter();
  /** Where a hand at arm's length before the camera's centre lands in the engine's world (m). */
  anchor: Vec3 = [0, 0, 0];
  /** Send both hands (the engine drives two: the hello's `second_hand`), else the one followed. */
  both = false;
  readonly state: WebcamState = { on: false, status: 'off', frames: 0, detected: 0, sent: 0, hands: [], detectMs: 0, fps: 0, width: 0, height: 0 };

  constructor(
    private readonly sender: RecordSink,
    private readonly preview: HTMLCanvasElement,
    private readonly changed: (state: WebcamState) => void,
  ) {}

  /** Starts the camera and the detection, or stops them. */
  async toggle(): Promise<void> {
    if (this.state.on) return this.stop();
    // Each start has its own number: a stop (or another start) while this one awaits the
    // camera or MediaPipe makes it give back what it opened and end.
    const start = ++this.starts;
    const current = () => start === this.starts && this.state.on;
    Object.assign(this.state, { on: true, frames: 0, detected: 0, sent: 0, detectMs: 0, fps: 0 });
    this.lastFrameAt = 0;
    this.report('starting the camera');
    let stream: MediaStream | null = null;
    try {
      // Browsers offer cameras (and WebXR) only to secure pages: https, or this machine.
      if (!navigator.mediaDevices) throw new Error(`no camera access for ${location.origin} (a browser gives it to https pages and to localhost only: open this page as http://localhost:${location.port})`);
      stream = await navigator.mediaDevices.getUserMedia({ video: { width: { ideal: 640 }, height: { ideal: 480 } }, audio: false });
      const video = Object.assign(document.createElement('video'), { muted: true, playsInline: true, srcObject: stream });
      await video.play();
      if (!current()) return stream.getTracks().forEach((t) => t.stop());
      this.video = video;
      Object.assign(this.state, { width: video.videoWidth, height: video.videoHeight });
      this.report('loading hand tracking');
      this.hands ??= loadHands((r) => this.results(r));
      await this.hands;
      if (!current()) return; // stopped while loading: stop() took the stream
      this.report('running');
      this.next();
    } catch (e) {
      if (!current()) return void stream?.getTracks().forEach((t) => t.stop());
      const reason = e instanceof DOMException ? `${e.name}: ${e.message}` : (e as Error).message;
      this.hands = null; // a failed load is tried again on the next start
      this.stop(`camera: ${reason}`);
    }
  }

  /** Stops the camera (the engine marks the hand lost after its grace time, and rests it). */
  stop(status = 'off'): void {
    this.starts++;
    this.state.on = false;
    const stream = this.video?.srcObject as MediaStream | null | undefined;
    stream?.getTracks().forEach((t) => t.stop());
    this.video = null;
    this.preview.hidden = true;
    this.report(status);
  }

  /** Gives MediaPipe the next camera frame once the previous one is done. */
  private next(): void {
    const video = this.video;
    if (!video || !this.state.on) return;
    const again = () => this.next();
    if ('requestVideoFrameCallback' in video) video.requestVideoFrameCallback(() => void this.detect(video).then(again));
    else requestAnimationFrame(() => void this.detect(video).then(again));
  }

  private async detect(video: HTMLVideoElement): Promise<void> {
    if (this.busy || !this.hands || video !== this.video) return;
    this.busy = true;
    const start = performance.now();
    try {
      await (await this.hands).send({ image: video });
    } catch (e) {
      this.stop(`hand tracking: ${(e as Error).message}`);
    } finally {
      this.busy = false;
    }
    const now = performance.now();
    const s = this.state;
    s.frames++;
    s.detectMs = s.frames === 1 ? now - start : (1 - SMOOTHING) * s.detectMs + SMOOTHING * (now - start);
    if (this.lastFrameAt > 0) s.fps = (1 - SMOOTHING) * s.fps + (SMOOTHING * 1000) / (now - this.lastFrameAt);
    this.lastFrameAt = now;
  }

  /** One frame's results: the followed hand to the engine, every hand on the preview. */
  private results(r: HandsResults): void {
    const video = this.video;
    if (!video) return;
    const image = r.multiHandLandmarks ?? [];
    const world = r.multiHandWorldLandmarks ?? [];
    const labels = (r.multiHandedness ?? []).map((h) => h.label);
    const followed = chosenHand(labels);
    const sides = labels.map(userSide);
    if (sides.length === 1) sides[0] = this.side.update(sides[0]);
    else this.side.reset(); // none, or two told apart by their labels
    this.state.hands = followed >= 0 ? [sides[followed], ...sides.filter((_, i) => i !== followed)] : [];
    if (followed >= 0) {
      this.state.detected++;
      const t = performance.now() / 1000;
      for (const k of handsToSend(sides, followed, this.both)) {
        const record = landmarkRecord(t, sides[k], world[k] ?? [], image[k] ?? [], video.videoWidth / video.videoHeight, this.anchor);
        if (record && this.sender.send(record)) this.state.sent++;
      }
    }
    this.drawPreview(video, image);
    this.changed(this.state);
  }

  /** The camera image and the landmarks, drawn as the camera sees them (CSS mirrors the canvas). */
  private drawPreview(video: HTMLVideoElement, hands: Point[][]): void {
    const canvas = this.preview;
    canvas.hidden = false;
    const { width, height } = canvas;
    const g = canvas.getContext('2d')!;
    g.drawImage(video, 0, 0, width, height);
    g.lineWidth = 2;
    g.strokeStyle = '#35d07f';
    g.fillStyle = '#e8453c';
    for (const hand of hands) {
      g.beginPath();
      for (const [a, b] of window.HAND_CONNECTIONS ?? []) {
        g.moveTo(hand[a].x * width, hand[a].y * height);
        g.lineTo(hand[b].x * width, hand[b].y * height);
      }
      g.stroke();
      for (const p of hand) g.fillRect(p.x * width - 2, p.y * height - 2, 4, 4);
    }
  }

  private report(status: string): void {
    this.state.status = status;
    this.changed(this.state);
  }
}

/**
 * Whether WebGL is drawn in software (SwiftShader, llvmpipe: no GPU). MediaPipe infers on
 * the GPU through WebGL by default; in software that is ~8 times slower than its own CPU
 * path (1.5 s against 0.18 s a frame in headless Chromium on a 2-core VM).
 */
function softwareWebGL(): boolean {
  const gl = document.createElement('canvas').getContext('webgl');
  if (!gl) return true;
  const info = gl.getExtension('WEBGL_debug_renderer_info');
  const renderer = String(gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER));
  gl.getExtension('WEBGL_lose_context')?.loseContext();
  return /swiftshader|llvmpipe|software/i.test(renderer);
}

/** Loads MediaPipe Hands from the page's build (its script once) and initialises it. */
async function loadHands(listener: (results: HandsResults) => void): Promise<Hands> {
  if (!window.Hands) {
    await new Promise<void>((resolve, reject) => {
      const script = Object.assign(document.createElement('script'), { src: `${MEDIAPIPE_DIR}hands.js`, crossOrigin: 'anonymous' });
      script.onload = () => resolve();
      script.onerror = () => reject(new Error(`${MEDIAPIPE_DIR}hands.js could not be loaded (is the page built with \`make viewer\`?)`));
      document.head.append(script);
    });
  }
  if (!window.Hands) throw new Error(`${MEDIAPIPE_DIR}hands.js did not define Hands`);
  const hands = new window.Hands({ locateFile: (file) => MEDIAPIPE_DIR + file });
  // The camera's own image: MediaPipe's labels are then swapped (landmarks.ts, userSide).
  hands.setOptions({ useCpuInference: softwareWebGL(), selfieMode: false, maxNumHands: 2, modelComplexity: 1, minDetectionConfidence: 0.5, minTrackingConfidence: 0.5 });
  hands.onResults(listener);
  await hands.initialize();
  return hands;
}
