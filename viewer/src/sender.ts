// The page's own live input (the webcam, a WebXR session) to the engine: one JSON record per
// message on the server's `/input` WebSocket. Records are live, so none is queued: one sent
// while the socket is not open is dropped (the engine would refuse it as late anyway), and
// the socket reopens on the next record after it closed.

/** The engine's answer to a refused record: `{"type": "error", "message": …}`. */
interface Refusal {
  type: 'error';
  message: string;
}

export class InputSender {
  private socket: WebSocket | null = null;
  /** Records handed to the socket. */
  sent = 0;
  /** Records dropped while the socket was not open. */
  dropped = 0;
  /** The engine's latest refusal of a record (it names the record and the problem), or null. */
  refusal: string | null = null;

  constructor(private readonly url: string) {}

  /** Sends one record now, or drops it (returns false) while the socket opens. */
  send(record: object): boolean {
    const socket = this.socket ?? this.open();
    if (socket.readyState !== WebSocket.OPEN) {
      this.dropped++;
      return false;
    }
    socket.send(JSON.stringify(record));
    this.sent++;
    return true;
  }

  /** Closes the socket (the engine then sees the input stop, and marks the hand lost). */
  close(): void {
    const socket = this.socket;
    this.socket = null;
    socket?.close();
  }

  private open(): WebSocket {
    const socket = new WebSocket(this.url);
    this.socket = socket;
    socket.onmessage = (event) => {
      try {
        const message = JSON.parse(String(event.data)) as Refusal;
        if (message.type === 'error') this.refusal = message.message;
      } catch {
        this.refusal = `unreadable answer from the engine: ${String(event.data).slice(0, 80)}`;
      }
    };
    socket.onclose = () => {
      if (this.socket === socket) this.socket = null;
    };
    return socket;
  }
}
