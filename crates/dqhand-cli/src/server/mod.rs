//! The viewer's local server: static files of the built page and the engine stream, both on
//! one port. One thread per connection: a slow or vanished browser only ever holds up its own
//! thread, never the engine of another viewer.

mod assets;
mod input_socket;
mod request;
mod socket;

use std::net::{SocketAddr, TcpListener, TcpStream};
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::Duration;

use dqhand::kinematics::JointModel;
use dqhand::model::Model;

use crate::feed::Feed;

/// Connections served at once; more are answered 503 (each holds a thread).
const MAX_CONNECTIONS: usize = 64;
/// Time a client has to send its request line and headers.
const REQUEST_TIMEOUT: Duration = Duration::from_secs(10);

/// What every connection shares.
pub struct Shared {
    /// The skinned hand every viewer poses (read-only; each viewer has its own pose).
    pub model: Arc<Model>,
    /// The joint model a new viewer starts with.
    pub joint_model: JointModel,
    /// The built page (`viewer/dist`), canonical; `None` serves the stream only.
    pub assets: Option<PathBuf>,
    /// Frames per second streamed to each viewer.
    pub fps: f64,
    /// The live input every viewer follows once it has records (the `/input` WebSocket
    /// feeds it, beside the demo's recording or UDP port); `None`: no input, no `/input`.
    pub feed: Option<Arc<Feed>>,
}

/// Accepts connections forever, one thread each.
pub fn serve(listener: TcpListener, shared: Shared) -> std::io::Result<()> {
    let bound = listener.local_addr()?;
    let shared = Arc::new(shared);
    let open = Arc::new(AtomicUsize::new(0));
    for stream in listener.incoming() {
        let Ok(stream) = stream else { continue };
        let (shared, open) = (Arc::clone(&shared), Arc::clone(&open));
        if open.fetch_add(1, Ordering::SeqCst) >= MAX_CONNECTIONS {
            open.fetch_sub(1, Ordering::SeqCst);
            let _ = request::respond(&stream, 503, "text/plain", b"too many connections\n", false);
            continue;
        }
        std::thread::spawn(move || {
            let peer = stream.peer_addr().ok();
            if let Err(e) = connection(stream, &shared, bound) {
                log_error(peer, &e);
            }
            open.fetch_sub(1, Ordering::SeqCst);
        });
    }
    Ok(())
}

fn log_error(peer: Option<SocketAddr>, e: &std::io::Error) {
    use std::io::ErrorKind::{BrokenPipe, ConnectionAborted, ConnectionReset, UnexpectedEof};
    if !matches!(e.kind(), BrokenPipe | ConnectionReset | ConnectionAborted | UnexpectedEof) {
        eprintln!("dqhand: {}: {e}", peer.map_or_else(|| "client".into(), |p| p.to_string()));
    }
}

/// One connection: a request for a file, or the upgrade to the engine stream.
fn connection(stream: TcpStream, shared: &Shared, bound: SocketAddr) -> std::io::Result<()> {
    stream.set_read_timeout(Some(REQUEST_TIMEOUT))?;
    stream.set_nodelay(true)?;
    let request = match request::Request::read(&stream).and_then(|r| r.check_host(bound).map(|()| r)) {
        Ok(r) => r,
        Err(request::Refusal { status, message }) => {
            return request::respond(&stream, status, "text/plain", format!("{message}\n").as_bytes(), false);
        }
    };
    let feed = shared.feed.as_deref().filter(|_| request.path == input_socket::PATH);
    if request.path == socket::PATH || feed.is_some() {
        match request.websocket_accept() {
            Ok(accept) => match feed {
                Some(feed) => input_socket::run(stream, request, &accept, feed),
                None => socket::run(stream, request, &accept, shared),
            },
            Err(request::Refusal { status, message }) => {
                request::respond(&stream, status, "text/plain", format!("{message}\n").as_bytes(), false)
            }
        }
    } else if let Some(root) = &shared.assets {
        assets::serve(&stream, &request, root)
    } else {
        request::respond(&stream, 404, "text/plain", b"not found\n", false)
    }
}
