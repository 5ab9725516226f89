// The WebSocket to the engine: acknowledges every frame at once (the server's flow control),
// and reconnects when the server goes away, replaying the page's settings to the new session.

import {
  binaryKind, decodeFrame, decodeText, decodeTopology, encodeCommand,
  type Command, type Frame, type Hello, type InputMessage, type LearningMessage, type RecordingMessage, type SceneMessage, type Topology,
} from './protocol';

export interface ConnectionEvents {
  hello(hello: Hello): void;
  topology(topology: Topology): void;
  frame(frame: Frame): void;
  /** The live input's state changed (only when the hello announces an input). */
  input(message: InputMessage): void;
  /** The scene's objects, the object held and the contacts (only when the hello has a scene). */
  scene(message: SceneMessage): void;
  /** A recording of the live input started or ended (the answer to a `record` command). */
  recording(message: RecordingMessage): void;
  /** How learning a gesture stands (the answer to a `learn` command). */
  learning(message: LearningMessage): void;
  error(message: string): void;
  status(connected: boolean): void;
}

const RETRY_MS = 500;

/** An engine's text message to the handler of its type (throws a `ProtocolError` for a bad one). */
export function dispatchText(text: string, events: ConnectionEvents): void {
  const message = decodeText(text);
  if (message.type === 'hello') events.hello(message);
  else if (message.type === 'input') events.input(message);
  else if (message.type === 'scene') events.scene(message);
  else if (message.type === 'recording') events.recording(message);
  else if (message.type === 'learning') events.learning(message);
  else events.error(message.message);
}

export class Connection {
  private socket: WebSocket | null = null;
  /** Commands that set up the view, replayed after a reconnect, by kind. */
  private settings = new Map<string, Command>();
  connected = false;
  framesReceived = 0;
  bytesReceived = 0;

  constructor(private readonly url: string, private readonly events: ConnectionEvents) {
    this.open();
  }

  private open(): void {
    const socket = new WebSocket(this.url);
    socket.binaryType = 'arraybuffer';
    this.socket = socket;
    socket.onopen = () => {
      this.connected = true;
      this.events.status(true);
      for (const c of this.settings.values()) socket.send(encodeCommand(c));
    };
    socket.onmessage = (event) => this.receive(event.data as string | ArrayBuffer);
    socket.onclose = () => {
      if (this.socket !== socket) return;
      this.connected = false;
      this.events.status(false);
      setTimeout(() => this.open(), RETRY_MS);
    };
  }

  private receive(data: string | ArrayBuffer): void {
    try {
      if (typeof data === 'string') {
        dispatchText(data, this.events);
        return;
      }
      this.bytesReceived += data.byteLength;
      const kind = binaryKind(data);
      if (kind === 'topology') this.events.topology(decodeTopology(data));
      else if (kind === 'frame') {
        const frame = decodeFrame(data);
        this.send({ type: 'ack', seq: frame.header.sequence });
        this.framesReceived++;
        this.events.frame(frame);
      } else this.events.error(`unknown binary message of ${data.byteLength} bytes`);
    } catch (e) {
      this.events.error((e as Error).message);
    }
  }

  /** Sends a command now (dropped while disconnected: the pose comes from the engine). */
  send(command: Command): void {
    if (this.socket?.readyState === WebSocket.OPEN) this.socket.send(encodeCommand(command));
  }

  /** Sends a setting and remembers it for the next session (view, heat map, limits, model). */
  setting(command: Command): void {
    this.remember(command);
    this.send(command);
  }

  /** Remembers a setting the engine already has (it changed it itself, e.g. on a gesture) without sending it. */
  remember(command: Command): void {
    this.settings.set(command.type, command);
  }
}
