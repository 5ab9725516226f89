//! The binary wire format of the viewer stream, version 2: the mesh topology once, then one
//! frame per engine step. Little-endian; every array starts on a 4-byte boundary, so the page
//! reads it through `Float32Array` / `Uint32Array` views without copying.
//!
//! Topology (`DQHT`):
//! ```text
//! 0  u32 magic "DQHT"   4 u16 version   6 u16 hand (0 the first, 1 the second)
//! 8  u32 vertex count   12 u32 index count   16 u32 joint count
//! 20 u32 indices[index count]   then i32 parent[joint count] (−1 for a root)
//! ```
//! Frame (`DQHF`):
//! ```text
//! 0  u32 magic "DQHF"   4 u16 version   6 u16 flags (bit 0: distortion arrays follow;
//!                                                   bit 1: of the second hand)
//! 8  u32 sequence number   12 u32 vertex count   16 u32 joint count   20 u32 DOF count
//! 24 u8 method per mesh ×4 (0 LB, 1 QB, 2 DQB, 3 CoR; 255 past the last): 1–4 meshes
//! 28 f32 engine time of this frame (pose + skin + distortion), µs
//! 32 f32 frames per second the engine is sending   36 f32 timeline time, s
//! 40 f32 timeline duration, s (0: no timeline)     44 u32 state (bit 0: playing; bit 1: limits on)
//! 48 f32 wrist translation xyz, rotation xyzw (world; the rig's rest wrist when none is set)
//! 76 f32 angles[DOF count] (radians)   then f32 joint positions[3 · joint count] (world)
//!    then per mesh: f32 positions[3 · vertex count], f32 normals[3 · vertex count],
//!                   (flag 0) f32 distortion[vertex count]
//! ```
//!
//! Version 1 held a mesh count at byte 24 and three method codes after it; version 2 holds
//! four codes there, so the split view can show all four methods, and the layout is otherwise
//! the same (the topology's too, whose version goes with the frame's).
//!
//! A server driving two hands (`dqhand demo --hands 2`) sends the second hand's topology after
//! the first's and, each step, the second hand's frame after the first's; its hello's
//! `second_hand` describes it (null with one hand).
//!
//! With a scene (`dqhand demo --scene`) two JSON texts join them. The hello's `scene` (null
//! without one; [`scene_hello`]): the table's top and each object's shape in its own frame,
//! metres, +Y up; a mesh's triangles scaled as the physics has them, at most
//! [`MAX_SCENE_TRIANGLES`] in all (a mesh past that is sent as its bounding box, 12 triangles,
//! with `"simplified": true`, so a huge mesh cannot make the hello huge):
//! ```json
//! {"table": {"height": 0.75, "centre": [0.0, -0.35], "half": [0.6, 0.4]},
//!  "objects": [{"name": "ball", "shape": "sphere", "radius": 0.04},
//!              {"name": "cube", "shape": "box", "size": [0.06, 0.06, 0.06]},
//!              {"name": "mug", "shape": "cylinder", "radius": 0.04, "height": 0.1},
//!              {"name": "teapot", "shape": "mesh", "positions": [0.1, 0.0, 0.02, …],
//!               "indices": [0, 1, 2, …], "simplified": false}]}
//! ```
//! Then, as the objects move ([`scene_message`]): the object held, every object's pose
//! (rotation `[x, y, z, w]`) and the rendered hand's contacts, at most [`MAX_SCENE_CONTACTS`]
//! (the bone touching, the point on the object, the object's normal there toward the hand):
//! ```json
//! {"type": "scene", "held": "ball", "objects": {"ball": {"p": [x, y, z], "q": [x, y, z, w]}, …},
//!  "contacts": [{"bone": "thumb-tip", "object": "ball", "p": [x, y, z], "n": [x, y, z]}]}
//! ```
//! Both stay bounded: a scene has at most [`MAX_SCENE_OBJECTS`] objects, named in at most
//! [`MAX_NAME_BYTES`] bytes ([`check_scene`]).

use serde_json::{json, Map, Value};

use dqhand::interaction::{scene_shapes, ManipulationLoop};
use dqhand::skin::{Method, MethodSet};
use crate::{Error, Result};

/// Version of the format written here; a reader refuses any other.
pub const VERSION: u16 = 2;
/// `"DQHF"` read as a little-endian `u32`.
pub const FRAME_MAGIC: u32 = u32::from_le_bytes(*b"DQHF");
/// `"DQHT"` read as a little-endian `u32`.
pub const TOPOLOGY_MAGIC: u32 = u32::from_le_bytes(*b"DQHT");
/// Bytes before the angles of a frame.
pub const FRAME_HEADER_BYTES: usize = 76;
/// Bytes before the indices of a topology message.
pub const TOPOLOGY_HEADER_BYTES: usize = 20;
/// Frame flag: a distortion array follows each mesh's normals.
pub const FLAG_DISTORTION: u16 = 1;
/// Frame flag: the frame is of the second hand (the hello's `second_hand`).
pub const FLAG_SECOND_HAND: u16 = 2;
/// Method code of a mesh slot past the frame's last mesh.
const UNUSED_METHOD: u8 = 255;
/// Mesh slots of a frame (bytes 24–27): fixed by the version, one per method today; a fifth
/// method would need a new version, so this stops the build rather than change the layout.
const SLOTS: usize = 4;
const _: () = assert!(SLOTS == Method::ALL.len());
/// State bit: the timeline is playing.
pub const STATE_PLAYING: u32 = 1;
/// State bit: angles are clamped to the anatomical limits.
pub const STATE_LIMITS: u32 = 2;

/// The scalar fields of a frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameHeader {
    /// Increases by one per frame sent to a client.
    pub sequence: u32,
    /// Vertices per mesh.
    pub vertex_count: u32,
    /// Joints with a position.
    pub joint_count: u32,
    /// Angles in the pose.
    pub dof_count: u32,
    /// The method of each mesh, in order (1–4 of them, distinct).
    pub methods: MethodSet,
    /// Whether each mesh carries a distortion array.
    pub distortion: bool,
    /// Whether the frame is of the second hand.
    pub second: bool,
    /// Engine time spent on this frame, µs.
    pub engine_us: f32,
    /// Frames per second the engine is sending to this client.
    pub engine_fps: f32,
    /// Timeline position, s.
    pub time: f32,
    /// Timeline length, s (0 when nothing is loaded).
    pub duration: f32,
    /// [`STATE_PLAYING`] | [`STATE_LIMITS`].
    pub state: u32,
    /// Wrist translation (m) and rotation `[x, y, z, w]` in world space: the pose's wrist,
    /// or the rig's rest wrist when the pose has none.
    pub wrist: [f32; 7],
}

impl FrameHeader {
    /// Meshes in the frame.
    #[must_use]
    pub fn mesh_count(&self) -> usize {
        self.methods.len()
    }

    /// Total size of the frame in bytes.
    #[must_use]
    pub fn byte_len(&self) -> usize {
        let v = self.vertex_count as usize;
        let per_mesh = 6 * v + if self.distortion { v } else { 0 };
        FRAME_HEADER_BYTES + 4 * (self.dof_count as usize + 3 * self.joint_count as usize + self.mesh_count() * per_mesh)
    }
}

/// Appends `values` as little-endian f32.
fn put_f32s(out: &mut Vec<u8>, values: &[f32]) {
    if cfg!(target_endian = "little") {
        out.extend_from_slice(bytemuck::cast_slice(values));
    } else {
        values.iter().for_each(|v| out.extend_from_slice(&v.to_le_bytes()));
    }
}

/// Builds a frame in a byte buffer: [`Self::begin`], then the pose, joints and meshes in the
/// order of the format. Appending never reallocates once the buffer has held one frame.
pub struct FrameWriter<'a> {
    out: &'a mut Vec<u8>,
    header: FrameHeader,
}

impl<'a> FrameWriter<'a> {
    /// Clears `out` and writes the header.
    pub fn begin(out: &'a mut Vec<u8>, header: FrameHeader) -> Self {
        out.clear();
        out.reserve(header.byte_len());
        let h = &header;
        out.extend_from_slice(&FRAME_MAGIC.to_le_bytes());
        out.extend_from_slice(&VERSION.to_le_bytes());
        let flags = if h.distortion { FLAG_DISTORTION } else { 0 } | if h.second { FLAG_SECOND_HAND } else { 0 };
        out.extend_from_slice(&flags.to_le_bytes());
        for v in [h.sequence, h.vertex_count, h.joint_count, h.dof_count] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        let mut codes = [UNUSED_METHOD; SLOTS];
        for (c, m) in codes.iter_mut().zip(h.methods.as_slice()) {
            *c = m.index() as u8;
        }
        out.extend(codes);
        put_f32s(out, &[h.engine_us, h.engine_fps, h.time, h.duration]);
        out.extend_from_slice(&h.state.to_le_bytes());
        put_f32s(out, &h.wrist);
        Self { out, header }
    }

    /// Appends f32 values (angles, joint positions, a mesh's arrays).
    pub fn floats(&mut self, values: &[f32]) -> &mut Self {
        put_f32s(self.out, values);
        self
    }

    /// Checks that the frame is complete.
    ///
    /// # Panics
    /// If fewer or more values were written than the header announces.
    pub fn finish(self) {
        assert_eq!(self.out.len(), self.header.byte_len(), "frame content does not match its header");
    }
}

/// A frame read back: the header and views of its arrays.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameView {
    /// The scalar fields.
    pub header: FrameHeader,
    /// Radians, one per DOF.
    pub angles: Vec<f32>,
    /// World joint positions, xyz per joint.
    pub joints: Vec<f32>,
    /// Per mesh: positions, normals (xyz per vertex) and distortion (empty without the flag).
    pub meshes: Vec<[Vec<f32>; 3]>,
}

fn bad(message: impl Into<String>) -> Error {
    Error::Frame(message.into())
}

/// Little-endian reader over a message that reports truncation as an error.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take(&mut self, n: usize) -> Result<&[u8]> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len());
        let end = end.ok_or_else(|| bad(format!("truncated at byte {} of {}", self.at, self.bytes.len())))?;
        let s = &self.bytes[self.at..end];
        self.at = end;
        Ok(s)
    }
    fn u16(&mut self) -> Result<u16> {
        Ok(u16::from_le_bytes(self.take(2)?.try_into().expect("2 bytes")))
    }
    fn u32(&mut self) -> Result<u32> {
        Ok(u32::from_le_bytes(self.take(4)?.try_into().expect("4 bytes")))
    }
    fn f32s(&mut self, n: usize) -> Result<Vec<f32>> {
        let bytes = self.take(n.checked_mul(4).ok_or_else(|| bad("array too long"))?)?;
        Ok(bytes.chunks_exact(4).map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes"))).collect())
    }
    /// Reads magic, version and flags; flag bits other than `known` are refused, since a
    /// later version may use them to change the layout.
    fn start(&mut self, magic: u32, what: &str, known: u16) -> Result<u16> {
        if self.u32()? != magic {
            return Err(bad(format!("not a {what} (wrong magic)")));
        }
        let version = self.u16()?;
        if version != VERSION {
            return Err(bad(format!("{what} version {version}, this reader knows {VERSION}")));
        }
        let flags = self.u16()?;
        if flags & !known != 0 {
            return Err(bad(format!("{what} flags {flags:#06x}: bits {:#06x} are unknown to version {VERSION}", flags & !known)));
        }
        Ok(flags)
    }
    fn end(&self) -> Result<()> {
        if self.at == self.bytes.len() {
            Ok(())
        } else {
            Err(bad(format!("{} bytes after the end", self.bytes.len() - self.at)))
        }
    }
}

impl FrameView {
    /// Parses a frame.
    ///
    /// # Errors
    /// [`Error::Frame`] for a wrong magic or version, an unknown method, or a length that
    /// does not match the header.
    pub fn parse(bytes: &[u8]) -> Result<Self> {
        let mut r = Reader { bytes, at: 0 };
        let flags = r.start(FRAME_MAGIC, "frame", FLAG_DISTORTION | FLAG_SECOND_HAND)?;
        let (sequence, vertex_count, joint_count, dof_count) = (r.u32()?, r.u32()?, r.u32()?, r.u32()?);
        let codes = r.take(SLOTS)?;
        let mesh_count = codes.iter().position(|&c| c == UNUSED_METHOD).unwrap_or(SLOTS);
        if mesh_count == 0 {
            return Err(bad("no meshes (method code 255 in the first slot)"));
        }
        let mut methods = [Method::Dqb; SLOTS];
        for (i, &c) in codes.iter().enumerate() {
            match (i < mesh_count, Method::ALL.get(usize::from(c))) {
                (true, Some(&m)) => methods[i] = m,
                (false, _) if c == UNUSED_METHOD => {}
                (true, None) => return Err(bad(format!("mesh {i}: method code {c}"))),
                (false, _) => return Err(bad(format!("mesh {i}: method code {c} after the last mesh ({mesh_count})"))),
            }
        }
        let methods = MethodSet::new(&methods[..mesh_count]).map_err(|e| bad(e.to_string()))?;
        let s = r.f32s(4)?;
        let state = r.u32()?;
        let wrist: [f32; 7] = r.f32s(7)?.try_into().expect("7 values");
        let header = FrameHeader {
            sequence,
            vertex_count,
            joint_count,
            dof_count,
            methods,
            distortion: flags & FLAG_DISTORTION != 0,
            second: flags & FLAG_SECOND_HAND != 0,
            engine_us: s[0],
            engine_fps: s[1],
            time: s[2],
            duration: s[3],
            state,
            wrist,
        };
        if header.byte_len() != bytes.len() {
            return Err(bad(format!("{} bytes, the header announces {}", bytes.len(), header.byte_len())));
        }
        let angles = r.f32s(dof_count as usize)?;
        let joints = r.f32s(3 * joint_count as usize)?;
        let v = vertex_count as usize;
        let mut meshes = Vec::with_capacity(mesh_count);
        for _ in 0..mesh_count {
            let d = if header.distortion { v } else { 0 };
            meshes.push([r.f32s(3 * v)?, r.f32s(3 * v)?, r.f32s(d)?]);
        }
        r.end()?;
        Ok(Self { header, angles, joints, meshes })
    }
}

/// The mesh and skeleton structure sent once per connection.
#[derive(Clone, Debug, PartialEq)]
pub struct Topology {
    /// Which hand: 0 the first, 1 the second (the hello's `second_hand`).
    pub hand: u16,
    /// Vertices of the mesh.
    pub vertex_count: u32,
    /// Triangle corners, three per triangle.
    pub indices: Vec<u32>,
    /// Parent of each joint (`None` for a root), for drawing the skeleton.
    pub parents: Vec<Option<usize>>,
}

impl Topology {
    /// Encodes the topology message.
    #[must_use]
    pub fn encode(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(TOPOLOGY_HEADER_BYTES + 4 * (self.indices.len() + self.parents.len()));
        out.extend_from_slice(&TOPOLOGY_MAGIC.to_le_bytes());
        out.extend_from_slice(&VERSION.to_le_bytes());
        out.extend_from_slice(&self.hand.to_le_bytes());
        for n in [self.vertex_count, self.indices.len() as u32, self.parents.len() as u32] {
            out.extend_from_slice(&n.to_le_bytes());
        }
        self.indices.iter().for_each(|i| out.extend_from_slice(&i.to_le_bytes()));
        self.parents.iter().for_each(|p| out.extend_from_slice(&p.map_or(-1, |p| p as i32).to_le_bytes()));
        out
    }

    /// Parses a topology message.
    ///
    /// # Errors
    /// [`Error::Frame`] for a wrong magic or version, a truncated message, an index out of
    /// range or a parent that is not another joint.
    pub fn parse(bytes: &[u8]) -> Result<Self> {
        let mut r = Reader { bytes, at: 0 };
        // The hand field is read as flags: 0 or 1, any other value refused.
        let hand = r.start(TOPOLOGY_MAGIC, "topology", 1)?;
        let (vertex_count, index_count, joint_count) = (r.u32()?, r.u32()? as usize, r.u32()? as usize);
        let indices = (0..index_count).map(|_| r.u32()).collect::<Result<Vec<_>>>()?;
        if let Some(i) = indices.iter().find(|&&i| i >= vertex_count) {
            return Err(bad(format!("index {i} with {vertex_count} vertices")));
        }
        let parents = (0..joint_count)
            .map(|j| match r.u32()? as i32 {
                -1 => Ok(None),
                p if p >= 0 && (p as usize) < joint_count && p as usize != j => Ok(Some(p as usize)),
                p => Err(bad(format!("joint {j}: parent {p} is not another joint"))),
            })
            .collect::<Result<Vec<_>>>()?;
        r.end()?;
        Ok(Self { hand, vertex_count, indices, parents })
    }
}

/// Triangles of mesh objects a hello carries at most, in all.
pub const MAX_SCENE_TRIANGLES: usize = 50_000;
/// Contacts a scene message carries at most.
pub const MAX_SCENE_CONTACTS: usize = 64;
/// Objects a streamed scene may have.
pub const MAX_SCENE_OBJECTS: usize = 256;
/// Bytes of an object's name in a streamed scene, at most.
pub const MAX_NAME_BYTES: usize = 64;

/// Whether the scene of `manip` fits the bounds of the scene messages.
///
/// # Errors
/// [`Error::Frame`] naming the bound the scene exceeds.
pub fn check_scene(manip: &ManipulationLoop) -> Result<()> {
    let names = manip.names();
    if names.len() > MAX_SCENE_OBJECTS {
        return Err(Error::Frame(format!("a scene of {} objects (the viewer takes at most {MAX_SCENE_OBJECTS})", names.len())));
    }
    match names.iter().find(|n| n.len() > MAX_NAME_BYTES) {
        Some(n) => Err(Error::Frame(format!("object name {n:?} is longer than {MAX_NAME_BYTES} bytes"))),
        None => Ok(()),
    }
}

/// The hello's `scene`: the table and the objects' shapes (see the module documentation).
#[must_use]
pub fn scene_hello(manip: &ManipulationLoop) -> Value {
    scene_shapes(manip, MAX_SCENE_TRIANGLES)
}

/// A `scene` message: the object held, the objects' poses and the contacts after the loop's
/// last step (see the module documentation). With two hands, `held` is the first hand's (in
/// the loop's order) that holds something, `holding` says what each side holds, and each
/// contact names its hand's side.
#[must_use]
pub fn scene_message(manip: &ManipulationLoop) -> String {
    let names = manip.names();
    let two = manip.hands().len() > 1;
    let objects: Map<String, Value> = names.iter().zip(manip.poses()).map(|(n, (q, p))| (n.clone(), json!({ "p": p.to_array(), "q": q.to_array() }))).collect();
    // Each hand's share of the bound: a hand touching much cannot crowd the other's out.
    let share = MAX_SCENE_CONTACTS / manip.hands().len();
    let contacts: Vec<Value> = manip
        .hands()
        .iter()
        .flat_map(|hand| {
            let joints = hand.rendered().skeleton().joints();
            hand.contacts().iter().take(share).map(move |c| {
                let mut contact = json!({ "bone": joints[c.joint].name, "object": names[c.object], "p": c.point.to_array(), "n": c.normal.to_array() });
                if two {
                    contact["hand"] = hand.side().name().into();
                }
                contact
            })
        })
        .collect();
    let held = manip.hands().iter().find_map(|h| h.held()).map(|i| &names[i]);
    let mut message = json!({ "type": "scene", "held": held, "objects": objects, "contacts": contacts });
    if two {
        message["holding"] = manip.hands().iter().map(|h| (h.side().name().to_owned(), h.held().map(|i| names[i].clone()).into())).collect::<Map<String, Value>>().into();
    }
    message.to_string()
}
