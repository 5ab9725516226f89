// The viewer page: runs the engine (in the page, WebAssembly; or in `dqhand demo`, over a
// WebSocket), draws its frames and turns controls into commands.

import './style.css';
import { Vector3 } from 'three';
import { Connection, type ConnectionEvents } from './connection';
import { heldText, InputPanel } from './input';
import { type Command, type Frame, type FrameHeader, type Hello, type Method, METHOD_LABELS, METHODS, type LearningMessage, type RecordingMessage } from './protocol';
import { HandScene } from './scene';
import { LocalConnection, type RelaySetup } from './local';
import { loadLook } from './look';
import { InputSender } from './sender';
import { Webcam } from './webcam';
import { WRIST_SLIDERS, wristCommand, wristSliderValues } from './wrist';
import { XRInput } from './xr';

const $ = <T extends HTMLElement>(id: string) => document.getElementById(id) as T;
const params = new URLSearchParams(location.search);
const figure = params.has('figure');
document.body.classList.toggle('figure', figure);

const scene = new HandScene($<HTMLCanvasElement>('view'));
const inputPanel = new InputPanel($);
const errors: string[] = [];
let hello: Hello | null = null;
let frame: Frame | null = null;
let dragging: HTMLInputElement | null = null;
let pageFps = 0;
/** Whether this connection's hello has set the scene (a server's scene is fixed; later hellos, as on a joint-model change, repeat it). */
let sceneSet = false;

const status = (text: string, kind: '' | 'ok' | 'error') => {
  const s = $('status');
  s.textContent = text;
  s.className = kind;
};

/**
 * Where the engine runs: asked (`?engine=page`: the page's own, on its own input;
 * `?engine=server`: `dqhand demo`'s, streamed), else as `engine.json` says: `dqhand demo`
 * answers it with its engine's settings, which the page runs following the live input the
 * server relays (or, where the page cannot rebuild that engine, `relay` is null and the page
 * shows the server's stream); a static host has no such file, and the page runs its own.
 */
async function engineSetup(): Promise<'page' | 'server' | RelaySetup> {
  const asked = params.get('engine');
  if (asked === 'page' || asked === 'server') return asked;
  try {
    const answer = await fetch('./engine.json', { cache: 'no-store', signal: AbortSignal.timeout(3000) });
    if (!answer.ok) return 'page';
    const engine = await answer.json();
    if (engine.engine !== 'dqhand demo') return 'page';
    if (typeof engine.relay !== 'string' || !engine.settings) return 'server';
    return { url: `${wsOrigin}${engine.relay}`, settings: JSON.stringify(engine.settings), hands: engine.hands };
  } catch {
    // No answer in 3 s, or one that is not JSON (a host that answers every path with a page).
    return 'page';
  }
}

const wsOrigin = `${location.protocol === 'https:' ? 'wss' : 'ws'}://${location.host}`;
const events: ConnectionEvents = {
  hello(h) {
    hello = h;
    const second = h.second_hand ? ` — and a ${h.second_hand.side} hand: ${h.second_hand.description}` : '';
    $('model-line').textContent = `${h.description}, ${h.triangles.toLocaleString()} triangles${second}`;
    // An engine driving two hands takes both of the user's, from the camera or the headset.
    webcam.both = xr.both = h.second_hand !== null;
    buildGestures(h);
    buildSliders(h);
    const select = $<HTMLSelectElement>('joint-model');
    select.replaceChildren(...h.joint_models.map((m) => new Option(`${m} (${m === h.joint_model ? h.dofs.length + ' DOF' : '…'})`, m, false, m === h.joint_model)));
    $<HTMLInputElement>('timeline').max = String(h.sequence.duration);
    inputPanel.setSource(h.input);
    webcam.anchor = cameraAnchor(h);
    if (!sceneSet) {
      sceneSet = true;
      scene.setScene(h.scene);
      inputPanel.setScene(h.scene !== null);
      // One hand among the objects: side by side, two of three would not be where the objects are.
      $<HTMLInputElement>('split').disabled = h.scene !== null;
    }
  },
  topology(t) {
    scene.setTopology(t);
    // The look (regions, materials, skin maps) from the hand's file: the page's, or the server's.
    const url = local ? local.handUrl(t.hand) : `/engine/hands/${t.hand === 1 ? 'left' : 'right'}.glb`;
    void loadLook(url, t).then((look) => look && scene.setLook(t, look));
  },
  frame(f) {
    // The controls and statistics follow the first hand; the second is only drawn.
    if (!f.header.second) {
      frame = f;
      followView(f.header);
    }
    scene.showFrame(f);
  },
  input(message) {
    inputPanel.update(message);
    if (message.mirrored !== mirrored) {
      mirrored = message.mirrored;
      showLive();
    }
  },
  scene(message) {
    scene.showScene(message);
    inputPanel.setHeld(heldText(message));
  },
  recording(message) {
    showRecording(message.on);
    const failed = message.failed ? ' — writing failed (disk full?): the records before are kept' : '';
    $('recording-status').textContent = message.on
      ? `recording to ${message.path}${failed}`
      : message.path ? `saved ${message.records.toLocaleString()} records to ${message.path}${failed}` : '';
    recordings.push(message);
  },
  learning(message) {
    inputPanel.setLearning(message);
    learnings.push(message);
  },
  error(message) {
    errors.push(message);
    status(`engine: ${message}`, 'error');
  },
  status(connected) {
    if (connected) inputPanel.reset();
    $<HTMLButtonElement>('record').disabled = !connected;
    showRecording(false); // a recording going on is announced by the new session
    sceneSet = false;
    status(connected ? (local ? (local.relayed ? 'engine in this page, following dqhand demo' : 'engine in this page') : 'connected') : 'disconnected — reconnecting…', connected ? 'ok' : '');
  },
};

/**
 * In the page: `?scene=NAME` puts the hand in a built-in scene, `&hands=2` both hands in it;
 * `&config=JSON` is the input configuration (as `dqhand demo --config` reads from a file).
 */
const setup = await engineSetup();
const local = setup === 'server' ? null : new LocalConnection(events, params.get('scene') ?? '', params.get('hands') === '2', params.get('config'), setup === 'page' ? null : setup);
const connection = local ?? new Connection(`${wsOrigin}/stream`, events);
/** The page's own live input to the engine: the camera's hand or an XR session's (with a server, to its input, which relays it back). */
const sender = local && !local.relayed ? local.input : new InputSender(`${wsOrigin}/input`);
const xr = new XRInput(scene.renderer, sender, $, {
  changed: () => {
    if (xr.active && webcam.state.on) webcam.stop('stopped for the VR or AR session');
    showLive();
  },
  error: (message) => status(message, 'error'),
});

// --- the user's own hand: camera and recording ------------------------------------------------
/** Whether the engine is recording the live input (as its last `recording` message said). */
let recording = false;
/** The `recording` messages received, oldest first (for the tests). */
const recordings: RecordingMessage[] = [];
/** The `learning` messages received, oldest first (for the tests). */
const learnings: LearningMessage[] = [];
/** Shows the Record button for a recording on or off. */
function showRecording(on: boolean): void {
  recording = on;
  $('record').classList.toggle('on', on);
  $('record').textContent = on ? 'Stop recording' : 'Record';
}
const webcam = new Webcam(sender, $<HTMLCanvasElement>('camera-preview'), (s) => {
  $('camera').textContent = s.on ? 'Stop camera' : 'Camera';
  $('camera-status').textContent = s.on && s.status === 'running'
    ? `${s.hands.length ? `following your ${s.hands[0]} hand` : 'no hand in view'} · ${s.detectMs.toFixed(0)} ms/frame · ${s.fps.toFixed(0)} fps`
    : s.status;
  showLive();
});
// One live source at a time (the engine follows one hand): a session stops the camera, and
// the camera waits for the session's end.
$('camera').addEventListener('click', () => {
  if (xr.active) $('camera-status').textContent = 'leave the VR or AR session first';
  else void webcam.toggle();
});
$('insecure').hidden = window.isSecureContext;
$('record').addEventListener('click', () => connection.send({ type: 'record', on: !recording }));
/** Learn (or record what is not) the gesture named in the Input panel, from the live hand. */
function learn(not: boolean): void {
  const name = $<HTMLInputElement>('learn-name').value.trim();
  if (!$<HTMLInputElement>('learn-name').reportValidity() || !name) return;
  connection.send({ type: 'learn', name, not });
}
$('learn-go').addEventListener('click', () => learn(false));
$('learn-not').addEventListener('click', () => learn(true));

/** Whether the engine shows the tracked hand as our hand's mirror image (a hand of the other side). */
let mirrored = false;
/** Whether the hand was drawn where the user's is, at the last `showLive`. */
let liveShown = false;
/**
 * Draws the hand where the user's is while this page's own input drives it (the camera, an
 * XR session), mirrored back when the engine mirrored it (not with a scene: there the
 * engine's contacts are those of the hand it poses); the camera behind and above it.
 */
function showLive(): void {
  const live = webcam.state.on || xr.active;
  scene.setWorld(live, mirrored && !scene.objects ? 'left' : 'right');
  if (live !== liveShown && !xr.active) scene.setView(live ? [0, 0.45, 1] : 'default', live ? new Vector3(...webcam.anchor) : undefined, live ? 0.6 : undefined);
  liveShown = live;
}

/** Where a hand before the camera lands: above the table's centre with a scene, else about where the resting hand is (m). */
function cameraAnchor(h: Hello): [number, number, number] {
  const table = h.scene?.table;
  return table ? [table.centre[0], table.height + 0.15, table.centre[1]] : [0, 0, -0.09];
}

// --- skinning view ---------------------------------------------------------------------------
const selectedMethod = (): Method => (METHODS.find((m) => $<HTMLInputElement>(`method-${m}`).checked) ?? 'dqb');
function sendView(): void {
  const split = $<HTMLInputElement>('split').checked;
  connection.setting({ type: 'view', methods: split ? [...METHODS] : [selectedMethod()] });
}
for (const m of METHODS) $(`method-${m}`).addEventListener('change', sendView);
$('split').addEventListener('change', sendView);
$('heatmap').addEventListener('change', () => {
  const on = $<HTMLInputElement>('heatmap').checked;
  $('legend').hidden = !on;
  connection.setting({ type: 'heatmap', on });
});

/** The methods and heat map of the previous frame ('' and null before the first). */
let viewShown = '';
let heatmapShown: boolean | null = null;
/**
 * Moves the skinning controls to what the frames show when that changes, whoever changed it
 * (the engine does on an input gesture's action), and remembers it as the settings to replay
 * after a reconnect. Only changes count: a click's own change arrives a few frames later.
 */
function followView(h: FrameHeader): void {
  const view = h.methods.join();
  if (view !== viewShown) {
    viewShown = view;
    const split = h.methods.length > 1;
    $<HTMLInputElement>('split').checked = split;
    if (!split) $<HTMLInputElement>(`method-${h.methods[0]}`).checked = true;
    connection.remember({ type: 'view', methods: [...h.methods] });
  }
  if (h.distortion !== heatmapShown) {
    heatmapShown = h.distortion;
    $<HTMLInputElement>('heatmap').checked = h.distortion;
    $('legend').hidden = !h.distortion;
    connection.remember({ type: 'heatmap', on: h.distortion });
  }
}
$('wireframe').addEventListener('change', () => scene.setWireframe($<HTMLInputElement>('wireframe').checked));
$('skeleton').addEventListener('change', () => (scene.showSkeleton = $<HTMLInputElement>('skeleton').checked));
$('limits').addEventListener('change', () => {
  connection.setting({ type: 'limits', on: $<HTMLInputElement>('limits').checked });
  if (hello) buildSliders(hello);
});
$('joint-model').addEventListener('change', () => connection.setting({ type: 'joint_model', name: $<HTMLSelectElement>('joint-model').value }));
$('rest').addEventListener('click', () => connection.send({ type: 'rest' }));

// --- gestures and timeline -------------------------------------------------------------------
function buildGestures(h: Hello): void {
  $('gestures').replaceChildren(
    ...h.gestures.map((name) => {
      const b = document.createElement('button');
      b.textContent = name;
      b.dataset.gesture = name;
      b.addEventListener('click', () => connection.send({ type: 'gesture', name }));
      return b;
    }),
  );
}
$('play').addEventListener('click', () => connection.send({ type: frame?.header.playing ? 'pause' : 'play' }));
$('timeline').addEventListener('input', () => connection.send({ type: 'seek', time: Number($<HTMLInputElement>('timeline').value) }));

// --- joint sliders ---------------------------------------------------------------------------
const FINGERS = ['thumb', 'index', 'middle', 'ring', 'pinky'];
function slider(label: string, min: number, max: number, step: number, onInput: (v: number) => void, data: Record<string, string>) {
  const row = document.createElement('label');
  row.className = 'slider';
  const input = document.createElement('input');
  Object.assign(input, { type: 'range', min: String(min), max: String(max), step: String(step), value: '0' });
  Object.assign(input.dataset, data);
  const out = document.createElement('output');
  out.textContent = '0';
  input.addEventListener('pointerdown', () => (dragging = input));
  input.addEventListener('pointerup', () => (dragging = null));
  input.addEventListener('input', () => {
    out.textContent = input.value;
    onInput(Number(input.value));
  });
  row.append(label, input, out);
  return row;
}

/** The slider of each DOF, in the hello's order (found once per rebuild, not per frame). */
let dofInputs: (HTMLInputElement | null)[] = [];
/** The wrist sliders, in `WRIST_SLIDERS`' order (built once, with the first hello). */
let wristInputs: HTMLInputElement[] = [];
/** The wrist of the latest frame as slider values, exactly (updated per animation frame). */
const _wrist = [0, 0, 0, 0, 0, 0];

function buildSliders(h: Hello): void {
  const limits = $<HTMLInputElement>('limits').checked;
  const groups = FINGERS.map((finger) => {
    const d = document.createElement('details');
    d.open = finger === 'index';
    const s = document.createElement('summary');
    s.textContent = finger;
    d.append(s);
    for (const dof of h.dofs.filter((x) => x.name.startsWith(finger))) {
      const name = dof.joint.replace(/^\S+ /, '') + ' ' + dof.name.split('.')[1];
      const [min, max] = limits ? [dof.min_deg, dof.max_deg] : [-180, 180];
      d.append(slider(name, min, max, 1, (deg) => connection.send({ type: 'angle', dof: dof.name, deg }), { dof: dof.name }));
    }
    return d;
  });
  $('sliders').replaceChildren(...groups);
  dofInputs = h.dofs.map((d) => $('sliders').querySelector<HTMLInputElement>(`input[data-dof="${d.name}"]`));
  if (wristInputs.length === 0) {
    // The touched slider's value, and the engine's own wrist (the latest frame's, exactly, not
    // as the other sliders round or clamp it) for the other five.
    const send = (i: number) => (value: number) => {
      const values = [..._wrist];
      values[i] = value;
      connection.send(wristCommand(values));
    };
    $('wrist').append(...WRIST_SLIDERS.map(({ label, min, max, step }, i) => slider(label, min, max, step, send(i), { wrist: String(i) })));
    wristInputs = Array.from($('wrist').querySelectorAll('input'));
  }
}

/** Shows a value on a slider and its output, unless the user is dragging that slider. */
function showValue(input: HTMLInputElement | null, value: number): void {
  if (!input || input === dragging || input.value === String(value)) return;
  input.value = String(value);
  input.nextElementSibling!.textContent = input.value;
}

/** Moves the sliders and the timeline to the engine's pose (except the one being dragged). */
function syncControls(f: Frame): void {
  wristSliderValues(f.header.wrist, _wrist);
  wristInputs.forEach((input, i) => showValue(input, _wrist[i]));
  if (!hello || f.angles.length !== hello.dofs.length) return;
  dofInputs.forEach((input, i) => showValue(input, Math.round((f.angles[i] * 180) / Math.PI)));
  const t = $<HTMLInputElement>('timeline');
  if (t !== dragging) t.value = String(f.header.time);
  $('time').textContent = `${f.header.time.toFixed(1)} / ${f.header.duration.toFixed(1)} s`;
  $('play').textContent = f.header.playing ? 'Pause' : 'Play';
}

// --- render loop and statistics --------------------------------------------------------------
let frames = 0;
let since = performance.now();
let engineUs = 0;
function loop(now: number, xrFrame?: XRFrame): void {
  xr.update(now, xrFrame);
  scene.render();
  if (frame) firstFrameMs ??= performance.now();
  frames++;
  if (now - since >= 1000) {
    pageFps = (frames * 1000) / (now - since);
    frames = 0;
    since = now;
  }
  if (frame) {
    engineUs = engineUs === 0 ? frame.header.engineUs : 0.9 * engineUs + 0.1 * frame.header.engineUs;
    syncControls(frame);
    const h = frame.header;
    $('stats').textContent =
      `page ${pageFps.toFixed(0)} fps   engine ${h.engineFps.toFixed(0)} fps\n` +
      `engine ${(engineUs / 1000).toFixed(2)} ms/frame (${h.methods.map((m) => METHOD_LABELS[m]).join(' + ')})\n` +
      `${(frame.byteLength / 1024).toFixed(0)} KiB/frame, ${h.vertexCount.toLocaleString()} vertices`;
    const labels = h.methods.length > 1 || figure ? scene.labelPositions() : [];
    const spans = $('labels');
    while (spans.childElementCount < labels.length) spans.append(document.createElement('span'));
    while (spans.childElementCount > labels.length) spans.lastElementChild!.remove();
    labels.forEach(({ method, x, y }, i) => {
      const span = spans.children[i] as HTMLElement;
      span.textContent = method ? METHOD_LABELS[method] : '';
      span.style.left = `${x}px`;
      span.style.top = `${y}px`;
    });
  }
}
/** When the first hand was drawn, ms after the page's navigation began (`make bench-web` reads it). */
let firstFrameMs: number | null = null;
// three.js's loop: the window's animation frames, or the XR session's while one runs.
scene.renderer.setAnimationLoop(loop);

// --- hooks for the browser tests and `make figures` ------------------------------------------
declare global {
  interface Window {
    dqhand: unknown;
  }
}
window.dqhand = {
  state: () => ({
    /** Where the engine runs: `'page'` (WebAssembly, here) or `'server'` (dqhand demo). */
    engine: local ? 'page' : 'server',
    /** The page's engine following `dqhand demo`'s relay: whether it is open, records received; null otherwise. */
    relay: local?.relay ? { open: local.relay.open, received: local.relay.received } : null,
    firstFrameMs,
    connected: connection.connected,
    framesReceived: connection.framesReceived,
    errors: [...errors],
    jointModel: hello?.joint_model ?? null,
    dofs: hello?.dofs.map((d) => d.name) ?? [],
    gestures: hello ? [...hello.gestures] : [],
    joints: hello ? [...hello.joints] : [],
    pageFps,
    visible: scene.visibleMethods(),
    /** The live input, null without one: tracking, the gesture now, record totals, the event log (newest first). */
    input: inputPanel.state(),
    /** The manipulation scene, null without one: the objects drawn (placed by a scene message), the one held, contacts shown, scene messages shown. */
    scene: scene.objects && { drawn: scene.objects.drawn(), held: scene.objects.held, contacts: scene.objects.contacts, updates: scene.objects.updates },
    /** The second hand (a server driving two), null without one: its side and its latest frame's wrist (world) and sequence number. */
    secondHand: hello?.second_hand
      ? {
          side: hello.second_hand.side,
          wrist: scene.secondFrame ? Array.from(scene.secondFrame.header.wrist) : null,
          sequence: scene.secondFrame?.header.sequence ?? null,
        }
      : null,
    geometries: scene.renderer.info.memory.geometries,
    /** Each hand's look from its file: its regions' material names in draw order while drawn in them, null otherwise. */
    looks: scene.looks(),
    /** The WebXR input: modes offered, the session, records sent, the side of the hand sent. */
    xr: xr.state(),
    /** The camera: on, status, frames given to MediaPipe and with a hand, records sent, hands seen, ms per detection, rate. */
    camera: { ...webcam.state, hands: [...webcam.state.hands] },
    /** The `recording` messages received, oldest first. */
    recordings: [...recordings],
    /** The `learning` messages received, oldest first. */
    learnings: [...learnings],
    frame: frame && {
      sequence: frame.header.sequence,
      methods: frame.header.methods,
      anglesDeg: Array.from(frame.angles, (a) => (a * 180) / Math.PI),
      joints: Array.from(frame.joints),
      wrist: Array.from(frame.header.wrist),
      playing: frame.header.playing,
      time: frame.header.time,
      engineFps: frame.header.engineFps,
      engineUs: frame.header.engineUs,
      distortion: frame.header.distortion,
    },
  }),
  send: (command: Command) => connection.send(command),
  /** Where each joint (`state().joints` order) of the first visible hand is drawn: fractions of the canvas from its top left. */
  jointsOnScreen: () => scene.jointsOnScreen(),
  /** Draws the hands in their looks (true) or in the plain skin material (the figures' before and after). */
  showLook: (on: boolean) => scene.showLook(on),
  /** Draws the second hand or leaves it out, to see what it draws. */
  showSecondHand: (on: boolean) => scene.showSecondHand(on),
  setting: (command: Command) => connection.setting(command),
  /**
   * Camera: 'default', 'side' or a direction, optionally close on a joint (by name) or on a
   * world point (m; with a scene, the engine's world the objects are in) at a distance (m).
   */
  view: (preset: 'default' | 'side' | [number, number, number], focus?: string | [number, number, number], distance?: number) => {
    if (Array.isArray(focus)) return scene.setView(preset, new Vector3(...focus), distance);
    const index = focus && hello ? hello.joints.indexOf(focus) : -1;
    scene.setView(preset, index >= 0 ? scene.jointPosition(index) ?? undefined : undefined, distance);
  },
};
