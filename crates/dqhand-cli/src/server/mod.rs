//! The viewer's local server: static files of the built page, the engine stream, and the
//! live input's relay to pages that run the engine themselves, all on one port. One thread per connection: a slow or vanished browser only ever holds up its own
//! thread, never the engine of another viewer.

mod assets;
mod input_socket;
mod messages;
mod page_engine;
mod relay_socket;
mod request;
mod socket;

use std::net::{SocketAddr, TcpListener, TcpStream};
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use dqhand::kinematics::JointModel;
use dqhand::hand::Side;
use dqhand::model::Model;

use crate::feed::Feed;
pub use page_engine::PageEngine;

/// Requests served at once (files, streams, input senders) once their heads are in; more are
/// answered 503.
const MAX_CONNECTIONS: usize = 64;
/// Connections still sending their request heads, counted apart so that they cannot take the
/// served ones' places (a client dripping a head a byte at a time holds only its own thread,
/// for [`HEAD_DEADLINE`]); more are answered 503 at once.
const MAX_PENDING_HEADS: usize = 512;
/// Time a client has for its whole request line and headers, however it spreads them.
const HEAD_DEADLINE: Duration = Duration::from_secs(5);

/// What every connection shares.
pub struct Shared {
    /// The skinned hand every viewer poses (read-only; each viewer has its own pose).
    pub model: Arc<Model>,
    /// The second hand and its side, when the live input drives two (`demo --hands 2`):
    /// every viewer shows it following the input's other hand.
    pub second: Option<(Arc<Model>, Side)>,
    /// The joint model a new viewer starts with.
    pub joint_model: JointModel,
    /// The built page (`viewer/dist`), canonical; `None` serves the stream only.
    pub assets: Option<PathBuf>,
    /// Frames per second streamed to each viewer.
    pub fps: f64,
    /// The live input every viewer follows once it has records (the `/input` WebSocket
    /// feeds it, beside the demo's recording or UDP port); `None`: no input, no `/input`.
    pub feed: Option<Arc<Feed>>,
    /// The engine a page runs itself, following the live input over `/relay`.
    pub page: PageEngine,
}

/// One place of a bounded count, taken while it lives.
struct Place(Arc<AtomicUsize>);

impl Place {
    /// A place of `count` if fewer than `max` are taken.
    fn take(count: &Arc<AtomicUsize>, max: usize) -> Option<Self> {
        (count.fetch_add(1, Ordering::SeqCst) < max).then(|| Self(Arc::clone(count))).or_else(|| {
            count.fetch_sub(1, Ordering::SeqCst);
            None
        })
    }
}

impl Drop for Place {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::SeqCst);
    }
}

/// The connection counts: heads still arriving, and requests being served.
#[derive(Default)]
struct Counts {
    heads: Arc<AtomicUsize>,
    served: Arc<AtomicUsize>,
}

/// Accepts connections forever, one thread each.
pub fn serve(listener: TcpListener, shared: Shared) -> std::io::Result<()> {
    let bound = listener.local_addr()?;
    let shared = Arc::new(shared);
    let counts = Arc::new(Counts::default());
    for stream in listener.incoming() {
        let Ok(stream) = stream else { continue };
        let Some(head) = Place::take(&counts.heads, MAX_PENDING_HEADS) else {
            let _ = request::respond(&stream, 503, "text/plain", b"too many connections\n", false);
            continue;
        };
        let (shared, counts) = (Arc::clone(&shared), Arc::clone(&counts));
        // Without a thread to spare the connection is dropped (its place with it), not the server.
        let _ = std::thread::Builder::new().spawn(move || {
            let peer = stream.peer_addr().ok();
            if let Err(e) = connection(stream, &shared, bound, head, &counts) {
                log_error(peer, &e);
            }
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

/// One connection: a request for a file, or the upgrade to the engine stream. `head` is this
/// connection's place among the heads still arriving, kept until its request is accepted (a
/// refusal lingers in it); a served place is taken only then.
fn connection(stream: TcpStream, shared: &Shared, bound: SocketAddr, head: Place, counts: &Counts) -> std::io::Result<()> {
    stream.set_nodelay(true)?;
    // A client that stops reading holds its thread no longer than this, a file's too.
    stream.set_write_timeout(Some(socket::WRITE_TIMEOUT))?;
    let read = request::Request::read(&stream, Instant::now() + HEAD_DEADLINE);
    let request = match read.and_then(|r| r.check_host(bound).map(|()| r)) {
        Ok(r) => r,
        Err(refusal) => return request::answer_refusal(&stream, &refusal),
    };
    let feed = shared.feed.as_ref().filter(|_| [input_socket::PATH, relay_socket::PATH].contains(&request.path.as_str()));
    let accept = if request.path == socket::PATH || feed.is_some() {
        match request.websocket_accept() {
            Ok(accept) => Some(accept),
            Err(refusal) => return request::answer_refusal(&stream, &refusal),
        }
    } else {
        None
    };
    drop(head);
    let Some(_served) = Place::take(&counts.served, MAX_CONNECTIONS) else {
        return request::answer_refusal(&stream, &request::refuse(503, "too many connections"));
    };
    match (accept, feed) {
        (Some(accept), Some(feed)) if request.path == relay_socket::PATH => relay_socket::run(stream, request, &accept, feed),
        (Some(accept), Some(feed)) => input_socket::run(stream, request, &accept, feed),
        (Some(accept), None) => socket::run(stream, request, &accept, shared),
        // The page asks what runs here (a static host has no such file: it runs its own engine).
        (None, _) if PageEngine::serves(&request.path) => shared.page.answer(&stream, &request, shared),
        (None, _) => match &shared.assets {
            Some(root) => assets::serve(&stream, &request, root),
            None => request::respond(&stream, 404, "text/plain", b"not found\n", false),
        },
    }
}
