//! The skin layer (paper 4.4): a mesh deformed by the kinematics layer's transforms with one
//! or several of LB, QB and DQB.

use std::sync::Arc;

use super::{Bones, Deformed, Deformer, Method, MethodSet, SelfContactPass, SkinnedMesh, VertexBuffers};

/// A skinned mesh with a deformer and an output per method of a [`MethodSet`], every buffer
/// allocated when a method joins the set; deforming allocates nothing.
///
/// It reads only the bones' transforms, so one kinematics layer can feed several skin layers
/// (one per viewer, one per method set), and a loop that only needs the skeleton (gesture
/// recognition, collision) holds no skin at all.
///
/// ```
/// use std::sync::Arc;
/// use dqhand::glam::{Affine3A, Quat, Vec3};
/// use dqhand::skin::{MeshData, Method, MethodSet, SkinLayer, SkinnedMesh, VertexBuffers};
///
/// // One triangle over two bones, its middle corner weighted half and half.
/// let (mesh, _warnings) = SkinnedMesh::new(MeshData {
///     positions: vec![[0.0, 0.0, 0.0], [0.01, 0.1, 0.0], [0.0, 0.2, 0.01]], stride: 2,
///     joints: vec![0, 1, 0, 1, 0, 1], weights: vec![1.0, 0.0, 0.5, 0.5, 0.0, 1.0],
///     indices: vec![0, 1, 2], inverse_bind: vec![Affine3A::IDENTITY; 2], ..MeshData::default()
/// })?;
/// // The bones' skinning transforms (or a `KinematicsLayer`, which carries them).
/// let skinning = vec![Affine3A::IDENTITY, Affine3A::from_rotation_translation(Quat::from_rotation_z(0.8), Vec3::Y * 0.05)];
/// let mut skin = SkinLayer::new(Arc::new(mesh), MethodSet::PAPER);
/// skin.deform(&skinning); // into the layer's own buffers, one per method
/// let mut positions = vec![0.0f32; 3 * 3]; // #V × 3: a renderer's vertex buffer, say
/// skin.deform_into(Method::Dqb, &skinning, VertexBuffers::Separate { positions: &mut positions, normals: None });
/// let dqb = skin.deformed(Method::Dqb).expect("DQB is in the set");
/// assert_eq!(positions.as_slice(), dqb.positions().as_flattened());
/// assert_ne!(skin.deformed(Method::Lb).expect("so is LB").positions()[1], dqb.positions()[1], "LB and DQB differ where bones blend");
/// # Ok::<(), dqhand::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct SkinLayer {
    mesh: Arc<SkinnedMesh>,
    methods: MethodSet,
    /// Per method, in [`Method::ALL`] order: its deformer, once it has been used.
    deformers: [Option<Deformer>; 4],
    /// Per method: its output, once it has been in the set.
    outputs: [Option<Deformed>; 4],
    /// Run after every method's deformation, where set.
    contact_pass: Option<SelfContactPass>,
}

impl SkinLayer {
    /// A skin layer deforming `mesh` with `methods` (positions and normals), on the fastest
    /// kernel this CPU runs, on the calling thread.
    #[must_use]
    pub fn new(mesh: Arc<SkinnedMesh>, methods: MethodSet) -> Self {
        let mut layer = Self { mesh, methods, deformers: Default::default(), outputs: Default::default(), contact_pass: None };
        layer.set_methods(methods);
        layer
    }

    /// The methods [`Self::deform`] runs; a method new to the layer gets its buffers here. A
    /// method joining the set follows the frames the set deformed (a joint twisted past 180°
    /// stays the way it turned in every view: [`Deformer::deform`]).
    pub fn set_methods(&mut self, methods: MethodSet) {
        let before = std::mem::replace(&mut self.methods, methods);
        for &m in methods.as_slice() {
            self.deformer(m);
            if !before.contains(m) {
                self.follow_the_set(m, before);
            }
            if self.outputs[m.index()].is_none() {
                self.outputs[m.index()] = Some(Deformed::new(&self.mesh));
            }
        }
    }

    /// Runs `pass` (built for this layer's mesh) after each method of every [`Self::deform`],
    /// so that the skin of one part of the hand stays out of another's; none: the deformers'
    /// skin as it is. [`Self::deform_into`] does not run it.
    pub fn set_contact_pass(&mut self, pass: Option<SelfContactPass>) {
        self.contact_pass = pass;
    }

    /// The next [`Self::deform`] does not follow the last one (a seek, another clip): see
    /// [`Deformer::forget_previous_frame`].
    pub fn forget_previous_frame(&mut self) {
        self.deformers.iter_mut().flatten().for_each(Deformer::forget_previous_frame);
    }

    /// `method`'s deformer takes the hemisphere signs of the first method of `set` that has
    /// them (not LB, not `method` itself). Allocates nothing.
    fn follow_the_set(&mut self, method: Method, set: MethodSet) {
        let Some(&source) = set.as_slice().iter().find(|&&m| m != Method::Lb && m != method) else { return };
        if let Ok([Some(to), Some(from)]) = self.deformers.get_disjoint_mut([method.index(), source.index()]) {
            to.follow(from);
        }
    }

    /// `method`'s deformer, made the first time (allocates then only).
    fn deformer(&mut self, method: Method) -> &mut Deformer {
        let mesh = &self.mesh;
        self.deformers[method.index()].get_or_insert_with(|| Deformer::new(method, mesh))
    }

    /// The mesh.
    #[must_use]
    pub fn mesh(&self) -> &Arc<SkinnedMesh> {
        &self.mesh
    }

    /// The methods [`Self::deform`] runs.
    #[must_use]
    pub fn methods(&self) -> MethodSet {
        self.methods
    }

    /// Deforms the mesh with every method of [`Self::methods`] by `bones` (a
    /// [`crate::kinematics::KinematicsLayer`], or #joints skinning transforms).
    ///
    /// # Panics
    /// If `bones` has another joint count than the mesh.
    pub fn deform<'a>(&mut self, bones: impl Into<Bones<'a>>) {
        let bones = bones.into();
        for &m in self.methods.as_slice() {
            let (Some(deformer), Some(out)) = (&mut self.deformers[m.index()], &mut self.outputs[m.index()]) else {
                unreachable!("every method of the set has its deformer and buffers")
            };
            deformer.deform(&self.mesh, bones, out);
            if let Some(pass) = &mut self.contact_pass {
                pass.apply(bones.skinning, out);
            }
        }
    }

    /// Deforms the mesh with `method` alone into the caller's memory (see
    /// [`Deformer::deform_into`]); the layer's own buffers are neither used nor made.
    ///
    /// # Panics
    /// As [`Self::deform`], and if a buffer's length is not the mesh's (#V × 3, or #V × 6
    /// interleaved).
    pub fn deform_into<'a>(&mut self, method: Method, bones: impl Into<Bones<'a>>, out: VertexBuffers<'_>) {
        let mesh = Arc::clone(&self.mesh);
        self.deformer(method).deform_into(&mesh, bones, out);
    }

    /// The mesh as `method` last deformed it: `None` if `method` was never in the set.
    #[must_use]
    pub fn deformed(&self, method: Method) -> Option<&Deformed> {
        self.outputs[method.index()].as_ref()
    }
}
