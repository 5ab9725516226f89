//! What arrives on the server's WebSockets: their size bounds, and what a viewer's message on
//! the stream asks for. Apart from the connection code (it needs only tungstenite and the
//! engine) so that the `websocket` fuzz target compiles it in and reads frames as the server does.

use dqhand_stream::Command;
use tungstenite::protocol::{Role, WebSocketConfig};
use tungstenite::{Message, WebSocket};

pub use dqhand_stream::MAX_COMMAND_BYTES;
/// Largest WebSocket message read at all; beyond it the connection is closed (after an
/// error message), since the rest of the message would have to be read to go on.
pub const MAX_WIRE_BYTES: usize = 64 * 1024;

/// The server's end of an upgraded connection; `rest` is what was read past the request head.
pub fn server_socket<S>(stream: S, rest: Vec<u8>) -> WebSocket<S> {
    let config = WebSocketConfig::default().max_message_size(Some(MAX_WIRE_BYTES)).max_frame_size(Some(MAX_WIRE_BYTES));
    WebSocket::from_partially_read(stream, rest, Role::Server, Some(config))
}

/// What a message from a viewer asks of its stream.
pub enum Incoming {
    /// A command for the session (acknowledgements included).
    Command(Command),
    /// Not a command: the error to answer with.
    Refused(String),
    /// The viewer leaves.
    Close,
    /// Nothing (a ping or pong: tungstenite answers pings itself).
    Nothing,
}

impl Incoming {
    pub fn of(message: Message) -> Self {
        match message {
            Message::Text(text) => Command::parse_bounded(&text).map_or_else(Self::Refused, Self::Command),
            Message::Binary(_) => Self::Refused("binary messages are not commands; send JSON text".into()),
            Message::Close(_) => Self::Close,
            Message::Ping(_) | Message::Pong(_) | Message::Frame(_) => Self::Nothing,
        }
    }
}
