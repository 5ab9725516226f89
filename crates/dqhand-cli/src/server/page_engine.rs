//! What the page learns from `engine.json`: that `dqhand demo` serves it, and how to run the
//! demo's engine itself: the settings ([`EngineSettings`]), the hands as skinned glTF files
//! (`/engine/hands/right.glb`, `/engine/hands/left.glb`) and the relay of the live input
//! ([`super::relay_socket`]). Where the page cannot rebuild the engine (a scene file, whose
//! meshes are this machine's files) `relay` is null, `why` says so, and the page shows the
//! server's stream instead.
//!
//! ```json
//! {"engine": "dqhand demo", "stream": "/stream", "relay": "/relay", "why": null,
//!  "settings": {"hands": 1, "scene": null, ...}, "hands": ["/engine/hands/right.glb"]}
//! ```

use std::net::TcpStream;
use std::sync::{Arc, OnceLock};

use dqhand::model::Model;
use dqhand_stream::EngineSettings;
use serde_json::json;

use super::request::{respond, Request};
use super::{relay_socket, socket, Shared};

/// Where the page asks.
pub const PATH: &str = "/engine.json";
/// Where the hands' files are, by side.
const HANDS: [&str; 2] = ["/engine/hands/right.glb", "/engine/hands/left.glb"];

/// The engine a page can run: its settings, or why it cannot, and the hands' files (written
/// when first asked for: fitting the collision proxies they carry takes a moment).
pub struct PageEngine {
    settings: Result<EngineSettings, String>,
    files: [OnceLock<Vec<u8>>; 2],
}

impl PageEngine {
    /// `settings`, or the reason a page cannot run this server's engine.
    pub fn new(settings: Result<EngineSettings, String>) -> Self {
        Self { settings, files: Default::default() }
    }

    /// Whether `path` is one of this module's.
    pub fn serves(path: &str) -> bool {
        path == PATH || HANDS.contains(&path)
    }

    /// Answers a GET or HEAD of [`PATH`] or of a hand's file.
    pub fn answer(&self, stream: &TcpStream, request: &Request, shared: &Shared) -> std::io::Result<()> {
        if !matches!(request.method.as_str(), "GET" | "HEAD") {
            return respond(stream, 405, "text/plain", b"only GET and HEAD\n", false);
        }
        let head = request.method == "HEAD";
        let models: Vec<&Arc<Model>> = std::iter::once(&shared.model).chain(shared.second.as_ref().map(|(m, _)| m)).collect();
        if let Some(k) = HANDS.iter().position(|&p| p == request.path) {
            return match models.get(k) {
                Some(model) => respond(stream, 200, "model/gltf-binary", self.files[k].get_or_init(|| dqhand::io::skinned_glb(model)), head),
                None => respond(stream, 404, "text/plain", b"not found: this server drives one hand\n", false),
            };
        }
        let relayed = self.settings.as_ref().ok().filter(|_| shared.feed.is_some());
        let settings = relayed.map(|s| {
            let mut s = s.clone();
            // The gestures now, learned ones included.
            if let Some(set) = shared.feed.as_ref().and_then(|f| f.input.gesture_set()) {
                s.gestures = set.to_json();
            }
            s
        });
        let why = match (&self.settings, &shared.feed) {
            (Err(why), _) => Some(why.as_str()),
            (Ok(_), None) => Some("this server has no live input to relay"),
            (Ok(_), Some(_)) => None,
        };
        let body = json!({
            "engine": "dqhand demo",
            "stream": socket::PATH,
            "relay": relayed.map(|_| relay_socket::PATH),
            "why": why,
            "settings": settings,
            "hands": &HANDS[..models.len()],
        });
        respond(stream, 200, "application/json", body.to_string().as_bytes(), head)
    }
}
