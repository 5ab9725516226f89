// `dqhand demo`'s live input for the engine in this page (crates/dqhand-cli/src/server/
// relay_socket.rs): every record the server's input takes (a glove, a recording played,
// another device's `/input`, this page's camera or headset) as a binary message holding its
// JSON line; `{"type": "reset_scene"}` where the scene starts over among them; the gestures
// recognised as `{"type": "gestures", "gestures": "<file text>"}`; the `recording` and
// `learning` messages of the stream. The page sends it `record` and `learn`
// only, what needs the server's disk and its learner. Reopened when the server goes away.

import { encodeCommand, type Command } from './protocol';

export interface RelayEvents {
  /** One record the server's input took: a JSON line. */
  record(line: string): void;
  /** The gestures recognised now (a gesture file's text). */
  gestures(text: string): void;
  /** The scene started over (a recording played again), in its place among the records. */
  resetScene(): void;
  /** Any other message (`recording`, `learning`, `error`): JSON text. */
  text(text: string): void;
  status(open: boolean): void;
}

const RETRY_MS = 500;

export class Relay {
  open = false;
  /** Records received. */
  received = 0;
  private socket: WebSocket | null = null;
  private readonly decoder = new TextDecoder();

  constructor(private readonly url: string, private readonly events: RelayEvents) {
    this.connect();
  }

  private connect(): void {
    const socket = new WebSocket(this.url);
    socket.binaryType = 'arraybuffer';
    this.socket = socket;
    socket.onopen = () => {
      this.open = true;
      this.events.status(true);
    };
    socket.onmessage = (event) => {
      const data = event.data as string | ArrayBuffer;
      if (typeof data !== 'string') {
        this.received++;
        this.events.record(this.decoder.decode(data));
        return;
      }
      // Rare (a state change), so read whole here: `gestures` and `reset_scene` are the relay's own.
      const message = JSON.parse(data) as { type?: string; gestures?: string };
      if (message.type === 'gestures' && typeof message.gestures === 'string') this.events.gestures(message.gestures);
      else if (message.type === 'reset_scene') this.events.resetScene();
      else this.events.text(data);
    };
    socket.onclose = () => {
      this.open = false;
      this.events.status(false);
      setTimeout(() => this.connect(), RETRY_MS);
    };
  }

  /** Sends `record` or `learn` (dropped while the relay is closed, as a server's stream drops it). */
  send(command: Command): void {
    if (this.socket?.readyState === WebSocket.OPEN) this.socket.send(encodeCommand(command));
  }
}
