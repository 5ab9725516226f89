//! WebSocket frames after an upgrade, read as the server reads them: its socket settings (the
//! 64 KiB message and frame bound) and its reading of each message (text is a command of at
//! most 4 KiB, binary is refused), compiled in as is, applied to a live session. Any bytes
//! give messages then an error, never a panic; no message read is over the bound; a refused
//! command changes nothing; and the session still writes frames its reader takes.
#![no_main]

use std::io::{Read, Write};
use std::sync::{Arc, LazyLock};

use dqhand::hand::{build, HandParams};
use dqhand::kinematics::JointModel;
use dqhand::model::Model;
use dqhand_stream::{Applied, FrameView, Session};
use libfuzzer_sys::fuzz_target;
use tungstenite::Message;

#[path = "../../crates/dqhand-cli/src/server/messages.rs"]
mod messages;

use messages::{Incoming, MAX_COMMAND_BYTES, MAX_WIRE_BYTES};

static HAND: LazyLock<Arc<Model>> = LazyLock::new(|| Arc::new(build(&HandParams { vertices: 1000, ..HandParams::default() }).unwrap()));

/// A client that has sent the fuzzer's bytes; what the server writes back (pongs, errors,
/// its close) goes nowhere.
struct Client<'a>(&'a [u8]);

impl Read for Client<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        self.0.read(buf)
    }
}

impl Write for Client<'_> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

fuzz_target!(|bytes: &[u8]| {
    let mut ws = messages::server_socket(Client(bytes), Vec::new());
    let mut session = Session::new(HAND.clone(), None, JointModel::Full).unwrap();
    // The server reads on after a timeout only; a client's bytes running out is an error.
    while let Ok(message) = ws.read() {
        assert!(message.len() <= MAX_WIRE_BYTES, "a message of {} bytes read", message.len());
        match Incoming::of(message) {
            Incoming::Command(command) => {
                let before = session.pose().clone();
                match session.apply(&command) {
                    // The server sends the new joint model's hello.
                    Ok(Applied::Hello) => drop(session.hello(MAX_COMMAND_BYTES, None)),
                    Ok(_) => {}
                    Err(_) => assert_eq!(session.pose(), &before, "a refused command changes nothing"),
                }
                session.advance(0.05);
            }
            // The server answers with the error and reads on, unless the answer cannot be sent.
            Incoming::Refused(error) => {
                if ws.send(Message::text(error)).is_err() {
                    break;
                }
            }
            Incoming::Close => break,
            Incoming::Nothing => {}
        }
    }
    let mut frame = Vec::new();
    session.render(60.0, &mut frame);
    FrameView::parse(&frame).expect("the session writes frames its reader takes");
});
