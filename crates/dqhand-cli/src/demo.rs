//! `dqhand demo`: the live viewer (a local server for the browser page), or with `--out` the
//! gesture library posed with LB, QB, DQB and CoR and written as files.

use std::net::{IpAddr, SocketAddr, TcpListener, UdpSocket};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicUsize;
use std::sync::Arc;
use std::time::Instant;

use anyhow::{bail, Context};
use dqhand::engine::{Engine, ModelSource};
use dqhand::gesture::GESTURES;
use dqhand::hand::Side;
use dqhand::input::Record;
use dqhand::io::PoseFile;
use dqhand::kinematics::JointModel;
use dqhand::interaction::GestureLoop;
use dqhand::model::Model;
use dqhand::scene::Scene;
use dqhand::skin::Method;
use dqhand::gesture::GestureSet;
use dqhand::input::{Calibration, InputConfig, MappingTable};
use dqhand_stream::{EngineSettings, LiveInput};

use crate::feed::Feed;
use crate::live::LiveRecords;
use crate::live_learning::LiveLearning;
use crate::relay::RecordRelay;
use crate::recording::{gesture_set, Format, InputArgs, RecordingReader};
use crate::server;
use crate::synthesize::TWO_HANDS_SCENE;

/// Arguments of `dqhand demo`.
#[derive(clap::Args)]
pub struct Args {
    /// Address to listen on. The default serves this machine only; 0.0.0.0 shares the viewer
    /// with the network (anyone who can reach it can watch and pose the hand).
    #[arg(long, default_value = "127.0.0.1")]
    host: IpAddr,
    /// Port to listen on (0: any free port; the URL printed says which).
    #[arg(long, default_value_t = 8080)]
    port: u16,
    /// Do not open a browser.
    #[arg(long)]
    no_open: bool,
    /// Frames per second streamed to each viewer.
    #[arg(long, default_value_t = 120.0, value_parser = parse_fps)]
    fps: f64,
    /// Joint model of the sliders at start (`paper` 18 DOF or `full` 23 DOF).
    #[arg(long, default_value = "full")]
    joint_model: JointModel,
    /// The hand: `builtin` or a skinned glTF with WebXR joint names.
    #[arg(long, default_value = "builtin")]
    model: ModelSource,
    /// The built page (default: viewer/dist here, else beside this program: viewer,
    /// ../share/dqhand/viewer, or the checkout's viewer/dist for target/release/dqhand).
    #[arg(long)]
    viewer: Option<PathBuf>,
    /// Instead of serving, write the gesture library posed with LB, QB, DQB and CoR (GLB), its
    /// pose files and the rigged hand into this directory.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Play this recording (glove CSV, joints or landmarks JSON lines) as the live input, in
    /// real time and over and over.
    #[arg(long, conflicts_with = "udp")]
    input: Option<PathBuf>,
    /// The recording's format (default: `.csv` is glove, anything else JSON lines).
    #[arg(long, requires = "input")]
    format: Option<Format>,
    /// Take live records on this UDP port, one JSON record per datagram, at --host.
    #[arg(long)]
    udp: Option<u16>,
    /// Record every live record taken (UDP, the /input WebSocket) to this file (JSON lines,
    /// replacing the file, each record written out as it is taken).
    #[arg(long)]
    record: Option<PathBuf>,
    /// Where the page's Record button writes its recordings (JSON lines, one new file per
    /// recording, named for the time).
    #[arg(long, default_value = "recordings")]
    recordings: PathBuf,
    #[command(flatten)]
    common: InputArgs,
    /// Gesture definitions to recognise instead of the built-in ones.
    #[arg(long)]
    gestures_file: Option<PathBuf>,
    /// Manipulate a scene: a built-in one (`grasp`, `objects`, `two-hands`) or a scene JSON
    /// file. Without --input or --udp a scripted grasp of each of its objects plays (made at
    /// start; in `two-hands` with two hands, its box carried between them and its bar handed
    /// over).
    #[arg(long)]
    scene: Option<String>,
    /// Hands the live input drives: 1, or 2 (a left and a right one, each built as itself,
    /// in a scene: --scene, else the built-in `two-hands`). Default: 2 in the `two-hands`
    /// scene, else 1.
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=2))]
    hands: Option<u8>,
    /// The left hand of two: `builtin` (the built-in hand built as a left one, at the
    /// defaults) or a skinned glTF of a left hand. --model is then the right hand.
    #[arg(long, default_value = "builtin")]
    left_model: ModelSource,
}

impl Args {
    /// Whether the live input drives two hands.
    fn two_hands(&self) -> bool {
        self.hands.map_or(self.scene.as_deref() == Some(TWO_HANDS_SCENE), |n| n == 2)
    }

    /// The scene manipulated, if any (two hands always have one).
    fn scene_name(&self) -> Option<&str> {
        self.scene.as_deref().or(self.two_hands().then_some(TWO_HANDS_SCENE))
    }
}


/// What a played input reads: a recording file, or records made at start.
enum Played {
    File(PathBuf),
    Records(Arc<[Record]>),
}

/// The recording `demo --scene` plays when no input is given: every object of the scene
/// grasped from above in turn by the demo's hand (`dqhand synthesize --scene` writes the same
/// for the built-in hand), or with a `left` hand in the `two-hands` scene its box carried
/// between both hands and its bar handed over; made now in memory; `None` for a scene without
/// objects.
fn scripted_grasps(model: &Arc<Model>, left: Option<&Arc<Model>>, name: &str, scene: &Scene) -> anyhow::Result<Option<Arc<[Record]>>> {
    if scene.objects.is_empty() {
        println!("input: {name} has no object to grasp, so nothing plays (give --input or --udp, or send records to /input)");
        return Ok(None);
    }
    let start = Instant::now();
    print!("scene {name}: making a scripted grasp of each object to play (synthetic, from the hand's own kinematics)... ");
    std::io::Write::flush(&mut std::io::stdout())?;
    let scripts = match left {
        Some(left) if name == TWO_HANDS_SCENE => crate::synthesize::two_handed([left, model], scene)?.1,
        _ => crate::synthesize::scripted_grasps(model, name, scene, Side::default()).with_context(|| name.to_owned())?.1,
    };
    let records: Arc<[Record]> = scripts.iter().flat_map(|s| s.records.iter().copied()).collect();
    println!("{} records in {} ms", records.len(), start.elapsed().as_millis());
    Ok(Some(records))
}

pub(crate) fn parse_fps(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(f) if (1.0..=1000.0).contains(&f) => Ok(f),
        _ => Err(format!("{s:?} is not a frame rate from 1 to 1000")),
    }
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    if let Some(out) = &args.out {
        return write_gestures(out);
    }
    let assets = viewer_dir(args.viewer.as_deref())?;
    let model = args.model.load()?;
    crate::warn_all(&model.warnings);
    let address = SocketAddr::new(args.host, args.port);
    let listener = TcpListener::bind(address).with_context(|| format!("cannot listen on {address} (try another --port)"))?;
    let bound = listener.local_addr()?;
    let model = Arc::new(model);
    let left = args.two_hands().then(|| args.left_model.left().load().with_context(|| format!("--left-model {}", args.left_model))).transpose()?.map(Arc::new);
    let (feed, settings) = live_input(args, &model, left.as_ref(), bound.ip())?;
    let url = format!("http://{}/", if bound.ip().is_unspecified() { SocketAddr::new([127, 0, 0, 1].into(), bound.port()) } else { bound });
    println!("{}", model.description);
    if bound.ip().is_loopback() {
        println!("listening on {bound}, this machine only (--host 0.0.0.0 to share with the network)");
    } else {
        println!("listening on {bound}: anyone who can reach this machine can watch and pose the hand");
    }
    println!("viewer: {url}");
    println!("press Ctrl-C to stop");
    if !args.no_open {
        open_browser(&url);
    }
    let second = left.map(|l| (l, Side::Left));
    let page = server::PageEngine::new(settings);
    let shared = server::Shared { model, second, joint_model: args.joint_model, assets: Some(assets), fps: args.fps, feed: Some(feed), page };
    server::serve(listener, shared)?;
    Ok(())
}

/// The live input: the recording played, or the UDP port, or only the `/input` WebSocket
/// (always open), each record recognised and every viewer following; with a `left` model,
/// of two hands. With it, the settings a page runs the same engine with, or why it cannot.
fn live_input(args: &Args, model: &Arc<Model>, left: Option<&Arc<Model>>, host: IpAddr) -> anyhow::Result<(Arc<Feed>, Result<EngineSettings, String>)> {
    let gestures = gesture_set(args.gestures_file.as_deref(), true)?.expect("recognition on");
    let mut config = args.common.config()?;
    if args.common.config.is_none() {
        // The default commands, for the gestures there are (another gesture file may lack them).
        config.actions.retain(|a| gestures.gestures().iter().any(|g| g.name() == a.gesture));
    }
    let mapper = Some(args.common.mapper(args.joint_model)?);
    let scene = args.scene_name().map(|name| Scene::named(name).map(|s| (name, s))).transpose()?;
    let played = match (&args.input, &scene, args.udp) {
        (Some(path), _, _) => Some(Played::File(path.clone())),
        (None, Some((name, scene)), None) => scripted_grasps(model, left, name, scene)?.map(Played::Records),
        (None, _, _) => None,
    };
    if let (Some(Played::File(input)), Some(record)) = (&played, &args.record) {
        if input.canonicalize().ok() == record.canonicalize().ok() {
            anyhow::bail!("{}: --record would replace the recording being played", record.display());
        }
    }
    let records = LiveRecords::new(&args.common, args.record.as_deref(), Some(args.recordings.clone()))?;
    let udp = match args.udp {
        Some(port) => {
            let address = SocketAddr::new(host, port);
            Some(UdpSocket::bind(address).with_context(|| format!("cannot receive on udp {address} (try another --udp port)"))?)
        }
        None => None,
    };
    let source = match (&played, &udp) {
        (Some(Played::File(path)), _) => path.display().to_string(),
        (Some(Played::Records(_)), _) => format!("scripted grasps in scene {} (synthetic)", args.scene_name().unwrap_or_default()),
        (None, Some(socket)) => format!("udp {}", socket.local_addr()?),
        (None, None) => "WebSocket /input".to_owned(),
    };
    let announce = played.is_some() || udp.is_some();
    let settings = page_settings(args, &config, &gestures)?.map(|s| EngineSettings { source: source.clone(), announce, ..s });
    let input = match scene {
        None => LiveInput::new(GestureLoop::new(Arc::clone(model), args.joint_model, mapper, config, Some(gestures))?, source.clone(), announce)?,
        Some((name, scene)) => {
            let manip = crate::grasp::manipulation_loop(Arc::clone(model), left.cloned(), args.joint_model, mapper, config, Some(gestures), &scene).with_context(|| name.to_owned())?;
            crate::warn_all(&manip.objects().warnings().iter().map(|w| format!("{name}: {w}")).collect::<Vec<_>>());
            let hands = if left.is_some() { "two hands, left and right" } else { "one hand" };
            println!("scene: {name}, {} objects ({}), {hands}", manip.names().len(), manip.names().join(", "));
            LiveInput::with_scene(manip, source.clone(), announce).with_context(|| name.to_owned())?
        }
    };
    let learning = LiveLearning::new(Arc::clone(model), args.common.config()?, Some(args.recordings.clone()));
    let relay = RecordRelay::new(records.sensors().to_vec());
    let feed = Arc::new(Feed { input, records, learning, relay, clients: AtomicUsize::new(0) });
    let reporter = Arc::clone(&feed);
    std::thread::spawn(move || reporter.report());
    let played_now = played.is_some();
    match played {
        Some(Played::File(path)) => {
            RecordingReader::open(&path, args.format, &args.common)?; // fail now, not in the thread
            let (feed, format, common, name) = (Arc::clone(&feed), args.format, args.common.clone(), source.clone());
            std::thread::spawn(move || {
                if let Err(e) = feed.play(&name, || RecordingReader::open(&path, format, &common)) {
                    eprintln!("dqhand: error: {e:#}");
                }
            });
        }
        Some(Played::Records(records)) => {
            let (feed, name) = (Arc::clone(&feed), source.clone());
            std::thread::spawn(move || {
                if let Err(e) = feed.play(&name, || Ok(RecordingReader::Records(Arc::clone(&records), 0))) {
                    eprintln!("dqhand: error: {e:#}");
                }
            });
        }
        None => {}
    }
    if played_now {
        println!("input: {source}, played in real time over and over");
    }
    if let Some(socket) = udp {
        println!("input: {source}, one JSON record per datagram");
        let feed = Arc::clone(&feed);
        std::thread::spawn(move || {
            if let Err(e) = feed.receive(&socket) {
                eprintln!("dqhand: error: {source}: {e}");
            }
        });
    }
    println!("input WebSocket: /input on this server, one JSON record per message");
    Ok((feed, settings))
}

/// What a page needs to run the demo's engine itself ([`EngineSettings`]), or why it cannot:
/// a scene file (its meshes are this machine's files).
///
/// # Errors
/// A glove table or calibration file that cannot be read (the demo reads them too).
fn page_settings(args: &Args, config: &InputConfig, gestures: &GestureSet) -> anyhow::Result<Result<EngineSettings, String>> {
    let scene = match args.scene_name() {
        Some(name) if !Scene::BUILTIN.contains(&name) => {
            return Ok(Err(format!("scene {name}: a scene file's meshes are this machine's files; the page shows this server's stream")));
        }
        name => name.map(str::to_owned),
    };
    let glove = match args.common.glove.as_str() {
        name if MappingTable::BUILTIN.contains(&name) => name.to_owned(),
        path => std::fs::read_to_string(path).with_context(|| format!("--glove {path}"))?,
    };
    let calibration = args.common.calib.as_deref().map(Calibration::load).transpose()?;
    let (hands, joint_model) = (1 + u8::from(args.two_hands()), args.joint_model.as_str().to_owned());
    Ok(Ok(EngineSettings { hands, scene, joint_model, config: config.clone(), gestures: gestures.to_json(), glove, calibration, ..EngineSettings::default() }))
}

/// The built page: `--viewer`, else the first of these with an `index.html`: `viewer/dist`
/// here (a checkout), then beside this program `viewer` (a copied program), then
/// `../share/dqhand/viewer` (an installed one: `bin/dqhand`), then `../../viewer/dist` (the
/// checkout's `target/release/dqhand`, run from elsewhere). Looked up when the program runs,
/// never where it was built.
fn viewer_dir(given: Option<&Path>) -> anyhow::Result<PathBuf> {
    if let Some(p) = given {
        anyhow::ensure!(p.join("index.html").is_file(), "{}: no index.html (give the directory of the built viewer)", p.display());
        return p.canonicalize().with_context(|| p.display().to_string());
    }
    let mut candidates = vec![PathBuf::from("viewer/dist")];
    if let Some(dir) = std::env::current_exe().ok().as_deref().and_then(Path::parent) {
        candidates.extend([dir.join("viewer"), dir.join("../share/dqhand/viewer"), dir.join("../../viewer/dist")]);
    }
    for c in &candidates {
        if c.join("index.html").is_file() {
            return c.canonicalize().with_context(|| c.display().to_string());
        }
    }
    let searched: Vec<String> = candidates.iter().map(|c| c.display().to_string()).collect();
    bail!(
        "the viewer is not built: no index.html in {}: run `make viewer` (or `make demo`) in the checkout, or give --viewer DIR",
        searched.join(", ")
    )
}

/// Opens `url` in the desktop's browser when there is a desktop; otherwise the printed URL
/// is all there is.
fn open_browser(url: &str) {
    let has_display = cfg!(any(target_os = "macos", windows))
        || std::env::var_os("DISPLAY").is_some()
        || std::env::var_os("WAYLAND_DISPLAY").is_some();
    if !has_display {
        println!("(no display: open the URL in a browser)");
        return;
    }
    let opener = if cfg!(target_os = "macos") { "open" } else if cfg!(windows) { "explorer" } else { "xdg-open" };
    let spawned = std::process::Command::new(opener)
        .arg(url)
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn();
    if spawned.is_err() {
        println!("(could not start {opener}: open the URL in a browser)");
    }
}

/// `--out`: every gesture posed with each method, as GLB and pose files, and the rigged hand.
fn write_gestures(out: &Path) -> anyhow::Result<()> {
    let model = Arc::new(ModelSource::Builtin(dqhand::hand::HandParams::default()).load()?);
    std::fs::create_dir_all(out).map_err(|e| anyhow::anyhow!("{}: {e}", out.display()))?;
    let rigged = out.join("hand.glb");
    dqhand::io::write_skinned_glb(&model, &rigged)?;
    println!("{}", model.description);
    println!("rigged, skinned hand: {}", rigged.display());
    let mut engine = Engine::new(model.clone(), JointModel::Full)?;
    println!("{:<10} {:>9} {:>9} {:>9} {:>9}  files", "gesture", "LB µs", "QB µs", "DQB µs", "CoR µs");
    for (i, g) in GESTURES.iter().enumerate() {
        let pose = g.pose(JointModel::Full);
        let stem = format!("{i:02}-{}", g.name);
        let pose_path = out.join(format!("{stem}.pose.json"));
        let file = PoseFile::from_pose(JointModel::Full, &pose);
        std::fs::write(&pose_path, serde_json::to_string_pretty(&file)?).map_err(|e| anyhow::anyhow!("{}: {e}", pose_path.display()))?;
        engine.kinematics_mut().pose(&pose);
        let mut times = Vec::new();
        for m in Method::ALL {
            let t = Instant::now();
            let posed = engine.skin_with(m);
            times.push(t.elapsed().as_secs_f64() * 1e6);
            let path = out.join(format!("{stem}.{m}.glb"));
            dqhand::io::write_posed(&path, posed.positions(), posed.normals(), model.mesh.uvs(), model.mesh.indices())?;
        }
        println!("{:<10} {:>9.1} {:>9.1} {:>9.1} {:>9.1}  {stem}.{{lb,qb,dqb,cor}}.glb, {stem}.pose.json", g.name, times[0], times[1], times[2], times[3]);
    }
    println!("(single frames, cold; `dqhand bench` gives medians over many frames)");
    Ok(())
}
