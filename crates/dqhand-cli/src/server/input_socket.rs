//! The `/input` WebSocket: live records from another program (a hand tracker, a glove
//! driver, a headset page), one JSON record per message, into the demo's live input. A
//! refused record is answered with an error message naming the problem; the stream goes on.
//! At most [`MAX_INPUT_CLIENTS`] senders at once, and one silent for [`IDLE`] is closed, so
//! senders cannot take the viewers' connections.

use std::net::TcpStream;
use std::sync::atomic::Ordering;
use std::time::Duration;

use tungstenite::Message;

use super::request::{answer_refusal, refuse, Request};
use super::socket::{read_failure, send_error, upgrade};
use crate::feed::{Feed, MAX_INPUT_CLIENTS};

/// The path of the input socket.
pub const PATH: &str = "/input";
/// A sender with no message for this long is closed.
const IDLE: Duration = Duration::from_secs(60);

/// Counts one `/input` connection while it lives.
struct Client<'a>(&'a Feed);

impl Drop for Client<'_> {
    fn drop(&mut self) {
        self.0.clients.fetch_sub(1, Ordering::SeqCst);
    }
}

/// Completes the handshake and takes records until the client leaves or goes silent.
pub fn run(stream: TcpStream, request: Request, accept: &str, feed: &Feed) -> std::io::Result<()> {
    if feed.clients.fetch_add(1, Ordering::SeqCst) >= MAX_INPUT_CLIENTS {
        feed.clients.fetch_sub(1, Ordering::SeqCst);
        return answer_refusal(&stream, &refuse(503, format!("{MAX_INPUT_CLIENTS} input senders already")));
    }
    let _client = Client(feed);
    let mut ws = upgrade(stream, request, accept)?;
    ws.get_ref().set_read_timeout(Some(IDLE))?;
    let mut record = feed.records.blank();
    loop {
        let message = match ws.read() {
            Ok(Message::Close(_)) => return Ok(()),
            Ok(m) => m,
            Err(e) => match read_failure(&mut ws, e) {
                Some(end) => return end,
                None => {
                    let _ = send_error(&mut ws, &format!("no record for {} s; closing", IDLE.as_secs()));
                    let _ = ws.close(None);
                    return ws.flush().map_err(std::io::Error::other);
                }
            },
        };
        let bytes: &[u8] = match &message {
            Message::Text(text) => text.as_bytes(),
            Message::Binary(bytes) => bytes,
            _ => continue,
        };
        if let Err(rejection) = feed.take(bytes, &mut record) {
            send_error(&mut ws, &rejection.to_string()).map_err(std::io::Error::other)?;
        }
    }
}
