// The page's own live input (the webcam, a WebXR session) to the engine: one JSON record per
// message on the server's `/input` WebSocket. Records are live, so none is queued: one sent
// while the socket is not open is dropped (the engine would refuse it as late anyway). A
// closed socket is opened again by a later record, after a wait that doubles while opening
// fails (the server down, or its senders full), so a page does not hammer it.

/** The first wait before opening the socket again, and the longest (ms). */
const RETRY_MS = [250, 5000] as const;

/** Where the page's live input goes: the server's `/input`, or the page's own engine. */
export interface RecordSink {
  /** Takes one record now, or drops it (false). */
  send(record: object): boolean;
  /** The records stop: the engine marks the hand lost after its grace time. */
  close(): void;
}

export class InputSender implements RecordSink {
  private socket: WebSocket | null = null;
  /** When the socket may be opened again (performance.now(), ms), and the wait after the next failure. */
  private retryAt = 0;
  private wait: number = RETRY_MS[0];

  constructor(private readonly url: string) {}

  /** Sends one record now, or drops it (returns false) while the socket is not open. */
  send(record: object): boolean {
    const socket = this.socket ?? (performance.now() >= this.retryAt ? this.open() : null);
    if (socket?.readyState !== WebSocket.OPEN) return false;
    socket.send(JSON.stringify(record));
    return true;
  }

  /** Closes the socket: the records stop, and the engine marks the hand lost after its grace time. */
  close(): void {
    const socket = this.socket;
    this.socket = null;
    socket?.close();
  }

  private open(): WebSocket {
    const socket = new WebSocket(this.url);
    this.socket = socket;
    socket.onopen = () => (this.wait = RETRY_MS[0]);
    socket.onclose = () => {
      if (this.socket !== socket) return;
      this.socket = null;
      this.retryAt = performance.now() + this.wait;
      this.wait = Math.min(2 * this.wait, RETRY_MS[1]);
    };
    return socket;
  }
}
