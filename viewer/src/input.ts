// The live input (`dqhand demo --input FILE` or `--udp PORT`) as the page shows it: source,
// tracking, the gesture recognised now, record counters and a log of gesture events and the
// actions they triggered. `InputLog` holds no DOM, so the tests run it in Node.

import type { HandState, HelloInput, InputMessage, LearningMessage, SceneMessage, Side, Tracking } from './protocol';

/** Entries the event log keeps. */
export const LOG_LENGTH = 30;

/** What the tracking badge says for each state. */
const TRACKING_TEXT: Record<Tracking, string> = { waiting: 'waiting for input', tracking: 'tracking', lost: 'tracking lost' };

/** The event log: one line per gesture event or action, newest first, at most `capacity` lines. */
export class InputLog {
  /** The lines, newest first. */
  readonly lines: string[] = [];

  constructor(readonly capacity = LOG_LENGTH) {}

  /**
   * Adds a message's events and actions, in time order (an event before an action at the same
   * time: the gesture's start triggers the action), so that the latest ends up first.
   */
  add(message: Pick<InputMessage, 'events' | 'actions'>): void {
    const entries = [
      ...message.events.map((e) => ({ t: e.t, order: 0, text: `${e.t.toFixed(2)}  ${e.hand ? `${e.hand} ` : ''}${e.event} ${e.gesture}` })),
      ...message.actions.map((a) => ({ t: a.t, order: 1, text: `${a.t.toFixed(2)}  ${a.gesture} → ${a.action}` })),
    ].sort((a, b) => a.t - b.t || a.order - b.order);
    for (const e of entries) this.lines.unshift(e.text);
    this.lines.length = Math.min(this.lines.length, this.capacity);
  }

  clear(): void {
    this.lines.length = 0;
  }
}

/** What the "holding" line says: the object held, or with two hands what each holds ("box in both hands", "left: cube, right: —"). */
export function heldText(message: Pick<SceneMessage, 'held' | 'holding'>): string {
  const h = message.holding;
  if (!h) return message.held ?? '—';
  if (h.left !== null && h.left === h.right) return `${h.left} in both hands`;
  return h.left === null && h.right === null ? '—' : `left: ${h.left ?? '—'}, right: ${h.right ?? '—'}`;
}

const percent = (share: number) => `${(share * 100).toFixed(share > 0 && share < 0.1 ? 1 : 0)} %`;

/** What the Input panel says of a gesture being learned (a `learning` message). */
export function learningText(m: LearningMessage): string {
  const name = m.name ?? '';
  switch (m.state) {
    case 'idle':
      return '';
    case 'recording':
      return m.not ? `show what is not ${name}, for ${m.seconds} s…` : `hold ${name}, for ${m.seconds} s…`;
    case 'training':
      return `learning ${name}…`;
    case 'noted':
      return `kept as not ${name}; now hold ${name} and press Learn`;
    case 'failed':
      return m.error ?? `learning ${name} failed`;
    case 'learned': {
      const r = m.report;
      if (!r) return `learned ${name}`;
      const not = r.notRate === null ? '' : `, on ${percent(r.notRate)} of what is not it`;
      const overlap = r.overlap.slice(0, 2).map((o) => `${o.gesture} ${percent(o.rate)}`).join(', ') || 'none';
      const saved = m.path ? `; saved to ${m.path}` : '';
      return `learned ${name}: recognised on ${percent(r.recall)} of its frames held back${not}; other gestures taken for it: ${overlap}; ${r.verdict}${saved}`;
    }
  }
}

/** The page's Input panel (hidden unless the hello announces an input) and the stage's "tracking lost" banner. */
export class InputPanel {
  /** The hello's input, or null when the demo has none. */
  source: HelloInput | null = null;
  tracking: Tracking = 'waiting';
  gesture: string | null = null;
  /** The tracked hand's side (null before a record). */
  side: Side | null = null;
  /** Whether our hand shows the tracked one mirrored (a hand of the other side). */
  mirrored = false;
  /** With two hands, each one's state (the first hand's first); null with one. */
  hands: HandState[] | null = null;
  accepted = 0;
  rejected = 0;
  readonly log = new InputLog();

  constructor(private readonly $: (id: string) => HTMLElement) {}

  /** Shows or hides the panel for a hello's input (a hello also comes after a joint-model change: the log stays). */
  setSource(input: HelloInput | null): void {
    this.source = input;
    this.$('input-panel').hidden = input === null;
    this.$('input-source').textContent = input?.source ?? '';
    this.$('input-gestures').textContent = input ? `recognises ${input.gestures.join(', ')}` : '';
    this.render();
  }

  /** Shows how learning a gesture stands; the Learn buttons wait while it records or trains. */
  setLearning(message: LearningMessage): void {
    const busy = message.state === 'recording' || message.state === 'training';
    for (const id of ['learn-go', 'learn-not']) (this.$(id) as HTMLButtonElement).disabled = busy;
    this.$('learn-status').textContent = learningText(message);
    this.$('learn-status').className = message.state;
  }

  /** Shows the "holding" line when the hand manipulates a scene. */
  setScene(on: boolean): void {
    this.$('holding').hidden = !on;
  }

  /** What the hands hold now (`heldText`). */
  setHeld(text: string): void {
    this.$('held').textContent = text;
  }

  /** Forgets the previous session's state (its counters and times restart with the new one). */
  reset(): void {
    Object.assign(this, { tracking: 'waiting', gesture: null, side: null, mirrored: false, hands: null, accepted: 0, rejected: 0 });
    this.setHeld('—');
    this.log.clear();
    this.render();
  }

  update(message: InputMessage): void {
    Object.assign(this, { tracking: message.tracking, gesture: message.gesture, side: message.side, mirrored: message.mirrored, hands: message.hands, accepted: message.accepted, rejected: message.rejected });
    this.log.add(message);
    this.render();
  }

  private render(): void {
    const badge = this.$('tracking');
    badge.textContent = TRACKING_TEXT[this.tracking];
    badge.className = `badge ${this.tracking}`;
    this.$('tracking-lost').hidden = this.source === null || this.tracking !== 'lost';
    this.$('gesture-now').classList.toggle('two', this.hands !== null);
    this.$('gesture-now').textContent = this.hands
      ? this.hands.map((h) => `${h.side}: ${h.tracking === 'tracking' ? h.gesture ?? '—' : TRACKING_TEXT[h.tracking]}`).join(', ')
      : this.gesture ?? '—';
    this.$('input-accepted').textContent = this.accepted.toLocaleString();
    this.$('input-rejected').textContent = this.rejected.toLocaleString();
    const list = this.$('input-log');
    list.replaceChildren(...this.log.lines.map((line) => Object.assign(document.createElement('li'), { textContent: line })));
  }

  /** The test hook's view: null without an input. */
  state(): { source: string; gestures: string[]; tracking: Tracking; gesture: string | null; side: Side | null; mirrored: boolean; hands: HandState[] | null; accepted: number; rejected: number; log: string[] } | null {
    if (!this.source) return null;
    const { tracking, gesture, side, mirrored, accepted, rejected } = this;
    const hands = this.hands && this.hands.map((h) => ({ ...h }));
    return { source: this.source.source, gestures: [...this.source.gestures], tracking, gesture, side, mirrored, hands, accepted, rejected, log: [...this.log.lines] };
  }
}
