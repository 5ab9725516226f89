// WebXR live input: in an immersive session with hand tracking, each XR frame's 25 joint poses
// of one tracked hand (of each, when the engine drives two) go to the engine as a record
// (`/input`), and the engine's hands are drawn where the user's are. The Enter VR / Enter AR buttons show only where the browser offers
// the mode; leaving the session gives the desktop view back (three.js restores the canvas).

import type { WebGLRenderer } from 'three';
import type { Side } from './protocol';
import type { RecordSink } from './sender';

export type XRMode = 'immersive-vr' | 'immersive-ar';

/** One joint of a record (crates/dqhand/src/input/json_record.rs): metres, `[x, y, z, w]`, radius. */
interface JointRecord {
  p: [number, number, number];
  q: [number, number, number, number];
  r?: number;
}

/** What the page's test hook reports. */
export interface XRState {
  supported: { vr: boolean; ar: boolean };
  active: boolean;
  mode: XRMode | null;
  /** Records the sender took (a closed socket drops them) in all sessions. */
  sent: number;
  /** The side of the hand last sent in this session (of two, the right one); null before its first record. */
  side: Side | null;
  /** Whether both hands are sent (the engine drives two). */
  both: boolean;
}

const MODES = { vr: 'immersive-vr', ar: 'immersive-ar' } as const;
/** The sides in order of preference: an engine driving one hand takes the right when tracked. */
const SIDES: readonly Side[] = ['right', 'left'];

export class XRInput {
  readonly supported = { vr: false, ar: false };
  mode: XRMode | null = null;
  side: Side | null = null;
  sent = 0;
  /** Send every tracked hand (the engine drives two: the hello's `second_hand`), else the preferred one. */
  both = false;
  /** Time (s) of the last record: the engine wants it strictly increasing. */
  private lastT = -Infinity;

  /**
   * `changed` hears a session start or end and a change of the side sent (the page then draws
   * the hand in the world or not); `error` hears a session refused.
   */
  constructor(
    private readonly renderer: WebGLRenderer,
    private readonly sender: RecordSink,
    $: (id: string) => HTMLElement,
    private readonly events: { changed(): void; error(message: string): void },
  ) {
    renderer.xr.enabled = true;
    renderer.xr.setReferenceSpaceType('local-floor'); // the engine's world: metres, +Y up, floor at 0
    for (const key of ['vr', 'ar'] as const) {
      const button = $(`enter-${key}`) as HTMLButtonElement;
      button.addEventListener('click', () => this.start(MODES[key]).catch((e: Error) => events.error(`${button.textContent}: ${e.message}`)));
      void navigator.xr?.isSessionSupported(MODES[key]).then((yes) => {
        this.supported[key] = yes;
        button.hidden = !yes;
      }, () => {});
    }
  }

  get active(): boolean {
    return this.mode !== null;
  }

  state(): XRState {
    return { supported: { ...this.supported }, active: this.active, mode: this.mode, sent: this.sent, side: this.side, both: this.both };
  }

  /** Starts a session that must track hands (a browser that cannot refuses it: `error`). */
  private async start(mode: XRMode): Promise<void> {
    if (this.active) return;
    const session = await navigator.xr!.requestSession(mode, { requiredFeatures: ['local-floor', 'hand-tracking'] });
    session.addEventListener('end', () => {
      this.mode = this.side = null;
      this.sender.close(); // the records stop: the engine marks the hand lost after its grace time
      this.events.changed();
    });
    await this.renderer.xr.setSession(session);
    this.mode = mode;
    this.events.changed();
  }

  /**
   * Sends the frame's tracked hand, the right one when all its joints are tracked, else the
   * left (with `both`, each hand all of whose joints are tracked); the render loop calls it
   * with the XR frame (none outside a session).
   */
  update(time: number, frame: XRFrame | undefined): void {
    const space = this.renderer.xr.getReferenceSpace();
    const t = time / 1000;
    if (!frame || !space || t <= this.lastT) return;
    let first: Side | null = null;
    for (const side of SIDES) {
      const hand = Array.from(frame.session.inputSources).find((s) => s.handedness === side)?.hand;
      const joints = hand && jointRecords(frame, hand, space);
      if (!joints) continue;
      this.lastT = t;
      if (this.sender.send({ t, hand: side, joints })) this.sent++;
      first ??= side;
      if (!this.both) break;
    }
    // The side reported is the first sent (the right one when both are).
    if (first !== null && first !== this.side) {
      this.side = first;
      this.events.changed();
    }
  }
}

/** The hand's joints in `space`, in XRHand's order (the engine's); null unless all are tracked. */
function jointRecords(frame: XRFrame, hand: XRHand, space: XRReferenceSpace): JointRecord[] | null {
  const joints: JointRecord[] = [];
  for (const joint of hand.values()) {
    const pose = frame.getJointPose?.(joint, space);
    if (!pose) return null;
    const { position: p, orientation: q } = pose.transform;
    joints.push({ p: [p.x, p.y, p.z], q: [q.x, q.y, q.z, q.w], r: pose.radius });
  }
  return joints;
}
