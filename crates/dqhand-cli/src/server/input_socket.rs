//! The `/input` WebSocket: live records from another program (a hand tracker, a glove
//! driver, a headset page), one JSON record per message, into the demo's live input. A
//! refused record is answered with an error message naming the problem; the stream goes on.

use std::net::TcpStream;

use tungstenite::Message;

use super::request::Request;
use super::socket::{read_failure, send_error, upgrade};
use crate::feed::Feed;

/// The path of the input socket.
pub const PATH: &str = "/input";

/// Completes the handshake and takes records until the client leaves.
pub fn run(stream: TcpStream, request: Request, accept: &str, feed: &Feed) -> std::io::Result<()> {
    let mut ws = upgrade(stream, request, accept)?;
    ws.get_ref().set_read_timeout(None)?;
    let mut record = feed.records.blank();
    loop {
        let message = match ws.read() {
            Ok(Message::Close(_)) => return Ok(()),
            Ok(m) => m,
            Err(e) => match read_failure(&mut ws, e) {
                Some(end) => return end,
                None => continue,
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
