// The engine in the page, with no server: the same engine `dqhand demo` runs for each viewer
// (crates/dqhand-wasm/src/local_stream.rs, in WebAssembly), speaking the same messages, so the
// page draws and controls it exactly as it does a server's. What a server does beside the
// engine, the page does itself: its live input (camera, WebXR) goes straight in, and a
// recording of it is saved as a file the browser downloads (it replays with `dqhand replay`).

import { LocalStream, wasmMemory } from '../../packages/dqhand/wasm/dqhand_wasm.js';
import { fetchModel, loadEngine } from '../../packages/dqhand/src/engine';
import { decodeFrame, decodeTopology, encodeCommand, type Command } from './protocol';
import { dispatchText, type ConnectionEvents } from './connection';
import { Relay } from './relay';
import type { RecordSink } from './sender';

/** `dqhand demo`'s engine, as its `engine.json` gives it: the page runs it and follows the relay. */
export interface RelaySetup {
  /** The relay's WebSocket URL. */
  url: string;
  /** The engine's settings (JSON text: crates/dqhand-stream/src/engine_settings.rs). */
  settings: string;
  /** The hands' files, right first. */
  hands: string[];
}

/** The engine's step rate (Hz): a timer's, which runs during an XR session too (the window's animation frames stop then). */
const RATE_HZ = 60;

/**
 * A hand as a skinned glTF file: the built-in one as `make viewer` writes it beside the page
 * (`hands/<side>.glb`, from `dqhand hand --out`), or `dqhand demo`'s. Loading it takes
 * milliseconds where generating it takes seconds in WebAssembly. Without the file (a build that
 * left it out, or a host that answers with something else), undefined: the engine generates the
 * built-in hand itself.
 */
async function handFile(url: string): Promise<Uint8Array | undefined> {
  const bytes = await fetchModel(url).catch(() => undefined);
  // A host that answers every path with the page (a single-page app's rewrite) gives no GLB.
  return bytes && bytes.length >= 12 && new TextDecoder().decode(bytes.subarray(0, 4)) === 'glTF' ? bytes : undefined;
}

/** The page's engine, driven by a timer; `send`, `setting` and `remember` as a server connection's. */
export class LocalConnection {
  connected = false;
  framesReceived = 0;
  bytesReceived = 0;
  /** Records taken into the engine, and refused by it. */
  sent = 0;
  refused = 0;
  private stream: LocalStream | null = null;
  private last = 0;
  /** The records of a recording going on (JSON lines), or null. */
  private recorded: string[] | null = null;
  private saved: { path: string | null; records: number } = { path: null, records: 0 };
  /** The page's live input (camera, WebXR) into this engine (relayed: the server's `/input` instead). */
  readonly input: RecordSink = { send: (record) => this.push(JSON.stringify(record)), close: () => {} };
  /** `dqhand demo`'s relay this engine follows, or null (a static host). */
  relay: Relay | null = null;

  /**
   * `scene`: a built-in scene's name or `''`; `twoHands`: a left hand too (a scene's); `config`:
   * an input configuration's JSON text (docs/formats.md), or null for the defaults. With
   * `relayed`, those are the server's instead, and its live input drives the engine.
   */
  constructor(private readonly events: ConnectionEvents, scene: string, twoHands: boolean, config: string | null, readonly relayed: RelaySetup | null = null) {
    void this.start(scene, twoHands, config);
  }

  /** The file of hand `hand` (0 the first, 1 the second), which also carries its look. */
  handUrl(hand: number): string {
    return this.relayed?.hands[hand] ?? ['./hands/right.glb', './hands/left.glb'][hand];
  }

  private async start(scene: string, twoHands: boolean, config: string | null): Promise<void> {
    const relayed = this.relayed;
    try {
      const urls = relayed?.hands ?? ['./hands/right.glb', ...(twoHands ? ['./hands/left.glb'] : [])];
      const [, right, left] = await Promise.all([loadEngine(), handFile(urls[0]), urls[1] ? handFile(urls[1]) : undefined]);
      // The demo's hand may be its --model: the built-in one generated instead would be another.
      if (relayed && (!right || (urls[1] && !left))) throw new Error(`${urls[right ? 1 : 0]}: the demo's hand could not be loaded`);
      this.stream = relayed ? LocalStream.fromSettings(relayed.settings, right, left) : new LocalStream(scene, twoHands, right, left, config ?? undefined);
    } catch (e) {
      this.events.error(`the page's engine: ${(e as Error).message}`);
      return;
    }
    // As a connection opens: the status first, then the engine's hello and topologies.
    this.connected = true;
    this.events.status(true);
    this.text(this.stream.hello());
    for (let k = 0; k < this.stream.handCount; k++) this.events.topology(decodeTopology(this.stream.topology(k).slice().buffer as ArrayBuffer));
    if (relayed) this.follow(relayed);
    this.last = performance.now();
    const timer = setInterval(() => {
      try {
        this.tick();
      } catch (e) {
        // The engine stopped (a trap in the WebAssembly): said once, and no more steps.
        clearInterval(timer);
        this.connected = false;
        this.events.error(`the page's engine stopped: ${(e as Error).message}`);
        this.events.status(false);
      }
    }, 1000 / RATE_HZ);
  }

  private tick(): void {
    const stream = this.stream!;
    const now = performance.now();
    const frames = stream.step((now - this.last) / 1000);
    this.last = now;
    for (const text of stream.takeTexts()) this.text(text);
    for (let k = 0; k < frames; k++) {
      // A copy: the engine writes its next frame over this one, and the page keeps frames.
      const [start, length] = [stream.framePtr(k), stream.frameLen(k)];
      const bytes = (wasmMemory().buffer as ArrayBuffer).slice(start, start + length);
      this.bytesReceived += bytes.byteLength;
      this.framesReceived++;
      try {
        this.events.frame(decodeFrame(bytes));
      } catch (e) {
        this.events.error((e as Error).message);
      }
    }
  }

  private text(text: string): void {
    try {
      dispatchText(text, this.events);
    } catch (e) {
      this.events.error((e as Error).message);
    }
  }

  /** Follows the server's relay: its records into the engine, its state messages to the page. */
  private follow(relayed: RelaySetup): void {
    let opened = false;
    // The gestures the engine has (the relay sends them on every connection).
    let gestures = (JSON.parse(relayed.settings) as { gestures: string }).gestures;
    this.relay = new Relay(relayed.url, {
      record: (line) => this.push(line),
      gestures: (text) => {
        if (text === gestures) return;
        try {
          this.stream!.setGestures(text);
          gestures = text;
        } catch (e) {
          this.events.error(`the relayed gestures: ${(e as Error).message}`);
        }
      },
      resetScene: () => this.stream!.resetScene(),
      text: (text) => this.text(text),
      status: (open) => {
        this.connected = open;
        // The engine's status was said when it loaded; a relay lost and found again is said too,
        // and the found one retold the engine's hello (the panel starts over on a status).
        if (opened || !open) this.events.status(open);
        if (opened && open) {
          this.text(this.stream!.hello());
          void this.reloadIfChanged(relayed.settings);
        }
        opened ||= open;
      },
    });
  }

  /** A demo restarted with other settings (glove, scene, hands): the page starts over on its engine. */
  private async reloadIfChanged(settings: string): Promise<void> {
    const setup = (text: string) => JSON.stringify({ ...(JSON.parse(text) as object), gestures: null });
    try {
      const engine = (await (await fetch('./engine.json', { cache: 'no-store' })).json()) as { settings: object | null };
      if (setup(JSON.stringify(engine.settings)) !== setup(settings)) location.reload();
    } catch {
      // No answer (the demo gone again): the relay reconnects, and this is asked again.
    }
  }

  /** Applies a command now (dropped before the engine has loaded); relayed, `record` and `learn` go to the server. */
  send(command: Command): void {
    if (!this.stream) return;
    if (this.relay && (command.type === 'record' || command.type === 'learn')) {
      this.relay.send(command);
      return;
    }
    try {
      const todo = this.stream.command(encodeCommand(command));
      if (todo === 'record') this.record(true);
      else if (todo === 'stop-recording') this.record(false);
    } catch (e) {
      this.events.error((e as Error).message);
    }
  }

  /** A setting: the page's engine lives as long as the page, so nothing is replayed later. */
  setting(command: Command): void {
    this.send(command);
  }

  remember(): void {}

  /** One record (a JSON line) of the live input into the engine (and the recording going on). */
  private push(line: string): boolean {
    if (!this.stream) return false;
    try {
      this.stream.push(line);
      this.sent++;
      this.recorded?.push(line);
      return true;
    } catch {
      this.refused++; // counted by the engine too, and shown in the Input panel
      return false;
    }
  }

  /** Starts a recording of the live input, or stops it and has the browser download it. */
  private record(on: boolean): void {
    if (on) {
      this.recorded ??= [];
    } else if (this.recorded) {
      const name = `dqhand-${new Date().toISOString().replace(/[:.]/g, '-')}.jsonl`;
      const url = URL.createObjectURL(new Blob(this.recorded.map((l) => `${l}\n`), { type: 'application/x-ndjson' }));
      const a = Object.assign(document.createElement('a'), { href: url, download: name });
      a.click();
      setTimeout(() => URL.revokeObjectURL(url), 10_000);
      this.saved = { path: name, records: this.recorded.length };
      this.recorded = null;
    }
    const { path, records } = on ? { path: 'a file this page downloads when you stop', records: 0 } : this.saved;
    this.events.recording({ type: 'recording', on, path, records, failed: false });
  }
}
