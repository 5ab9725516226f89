//! The built-in hand's appearance (issue 32): its triangles in three regions (back, palm,
//! nails) that together are the whole mesh, nails where nails are, and skin maps whose
//! creases lie where the mesh's own UVs put the joints; and the glTF that carries them, read
//! back over the same vertices.

use dqhand::appearance::{SkinImage, SurfaceRegion};
use dqhand::hand::{build, HandParams, Side};
use dqhand::kinematics::webxr;
use dqhand::model::Model;
use glam::{Vec2, Vec3};

fn hand(params: HandParams) -> Model {
    build(&params).unwrap_or_else(|e| panic!("{params:?}: {e}"))
}

fn joint(name: &str) -> usize {
    webxr::JOINT_NAMES.iter().position(|&n| n == name).unwrap()
}

/// Each triangle's region, read from the appearance's ranges.
fn regions(model: &Model) -> Vec<SurfaceRegion> {
    let appearance = model.appearance.as_ref().expect("the built-in hand has an appearance");
    let mut out = Vec::new();
    let mut end = 0;
    for (region, range) in &appearance.regions {
        assert_eq!(range.start, end, "{region:?}: the ranges follow each other");
        assert_eq!(range.len() % 3, 0);
        out.extend(std::iter::repeat_n(*region, range.len() / 3));
        end = range.end;
    }
    assert_eq!(end, model.mesh.indices().len(), "the regions hold every triangle");
    out
}

#[test]
fn every_finger_has_a_nail_on_the_back_of_its_last_phalanx() {
    for side in [Side::Right, Side::Left] {
        let model = hand(HandParams { side, ..HandParams::default() });
        let positions = model.mesh.positions();
        let world = model.skeleton.rest_world();
        let regions = regions(&model);
        let mut area = [0.0f32; 5];
        let mut sides = [0.0f32; 2];
        for (t, tri) in model.mesh.indices().chunks_exact(3).enumerate() {
            let [a, b, c] = [0, 1, 2].map(|k| Vec3::from(positions[tri[k] as usize]));
            let (centre, normal) = ((a + b + c) / 3.0, (b - a).cross(c - a));
            match regions[t] {
                SurfaceRegion::Nail => {
                    // On the distal phalanx of the nearest finger, facing out of its back.
                    let (f, distal) = (0..5)
                        .map(|f| (f, joint(&format!("{}-phalanx-distal", webxr::FINGERS[f]))))
                        .min_by(|x, y| Vec3::from(world[x.1].translation).distance(centre).total_cmp(&Vec3::from(world[y.1].translation).distance(centre)))
                        .unwrap();
                    let (start, tip) = (Vec3::from(world[distal].translation), Vec3::from(world[distal + 1].translation));
                    let along = (centre - start).dot((tip - start).normalize()) / start.distance(tip);
                    assert!((-0.1..1.2).contains(&along), "{side:?}: a nail triangle {along:.2} along the distal phalanx of finger {f}");
                    let dorsal = Vec3::from(world[distal].matrix3.y_axis);
                    assert!(normal.normalize().dot(dorsal) > 0.3, "{side:?}: a nail triangle facing {normal} on finger {f}, whose back is {dorsal}");
                    area[f] += normal.length() / 2.0;
                }
                SurfaceRegion::Palm => sides[1] += normal.length() / 2.0,
                SurfaceRegion::Back => sides[0] += normal.length() / 2.0,
            }
        }
        // The back and the palm are each about half the skin.
        assert!((0.75..1.33).contains(&(sides[0] / sides[1])), "{side:?}: back {:.0} cm², palm {:.0} cm²", sides[0] * 1e4, sides[1] * 1e4);
        // A nail of an adult hand: some 40–120 mm² (the thumb's largest).
        for (f, a) in area.iter().enumerate() {
            assert!((25e-6..160e-6).contains(a), "{side:?}: finger {f}'s nail is {:.0} mm²", a * 1e6);
        }
        assert!(area[0] > area[4], "the thumb's nail is larger than the little finger's: {area:?}");
    }
}

/// The albedo's luminance (sRGB bytes, Rec. 709 weights) at texture coordinates `uv`.
fn luminance(image: &SkinImage, uv: [f32; 2]) -> f32 {
    let (x, y) = ((uv[0] * image.width as f32) as usize, (uv[1] * image.height as f32) as usize);
    let p = &image.rgb[3 * (y.min(image.height as usize - 1) * image.width as usize + x.min(image.width as usize - 1))..][..3];
    0.2126 * f32::from(p[0]) + 0.7152 * f32::from(p[1]) + 0.0722 * f32::from(p[2])
}

/// The texture coordinates the mesh's own UVs give a point of the palm plane (x, z): the
/// affine map fitted to every vertex's UV, which is exact for the built-in hand's projection.
fn uv_map(model: &Model) -> impl Fn(Vec3) -> [f32; 2] {
    let positions = model.mesh.positions();
    let uvs = model.mesh.uvs();
    // Least squares of u and v on (x, z, 1), in f64.
    let mut ata = glam::DMat3::ZERO;
    let (mut atu, mut atv) = (glam::DVec3::ZERO, glam::DVec3::ZERO);
    for (p, uv) in positions.iter().zip(uvs) {
        let a = glam::DVec3::new(f64::from(p[0]), f64::from(p[2]), 1.0);
        ata += glam::DMat3::from_cols(a * a.x, a * a.y, a * a.z);
        atu += a * f64::from(uv[0]);
        atv += a * f64::from(uv[1]);
    }
    let inverse = ata.inverse();
    let (cu, cv) = (inverse * atu, inverse * atv);
    let map = move |p: Vec3| {
        let a = glam::DVec3::new(f64::from(p.x), f64::from(p.z), 1.0);
        [a.dot(cu) as f32, a.dot(cv) as f32]
    };
    let worst = positions.iter().zip(uvs).map(|(&p, uv)| Vec2::from(map(p.into())).distance(Vec2::from(*uv))).fold(0.0, f32::max);
    assert!(worst < 1e-5, "the UVs are one planar projection: off by {worst}");
    map
}

#[test]
fn the_creases_lie_at_the_joints_where_the_meshs_uvs_put_them() {
    let model = hand(HandParams::default());
    let world = model.skeleton.rest_world();
    let appearance = model.appearance.as_ref().unwrap();
    let [back, palm] = appearance.maps();
    let (back, palm) = (&back, &palm);
    let uv = uv_map(&model);
    for map in [&palm.albedo, &palm.normal, &back.albedo, &back.normal] {
        assert_eq!(map.rgb.len(), 3 * (map.width * map.height) as usize);
    }
    for finger in ["index-finger", "middle-finger", "ring-finger", "pinky-finger"] {
        let [pip, dip] = ["intermediate", "distal"].map(|b| Vec3::from(world[joint(&format!("{finger}-phalanx-{b}"))].translation));
        let mid = pip.lerp(dip, 0.5);
        // The PIP's crease on the palm (the darkest within 1.5 mm of the joint along the
        // finger) is darker than the middle of the phalanx beyond it is.
        let darkest = |at: Vec3| (-15..=15).map(|k| luminance(&palm.albedo, uv(at + (dip - pip).normalize() * (k as f32 * 1e-4)))).fold(f32::INFINITY, f32::min);
        let (crease, between) = (darkest(pip), darkest(mid));
        assert!(crease < 0.93 * between, "{finger}: PIP crease {crease:.0} against {between:.0} mid-phalanx");
        // Its normal map tilts across the crease's edges, and hardly mid-phalanx.
        let tilt = |uv: [f32; 2]| {
            let (x, y) = ((uv[0] * palm.normal.width as f32) as usize, (uv[1] * palm.normal.height as f32) as usize);
            (0..9usize)
                .map(|dy| {
                    let p = &palm.normal.rgb[3 * ((y + dy - 4) * palm.normal.width as usize + x)..][..3];
                    (f32::from(p[0]) - 127.5).hypot(f32::from(p[1]) - 127.5)
                })
                .fold(0.0, f32::max)
        };
        let (at_crease, at_mid) = (tilt(uv(pip)), tilt(uv(mid)));
        assert!(at_crease > 3.0 * at_mid.max(4.0), "{finger}: normals tilt {at_crease:.0} at the crease, {at_mid:.0} mid-phalanx");
    }
}

#[test]
fn each_nail_is_painted_where_its_own_skin_reads_the_back_map() {
    for side in [Side::Right, Side::Left] {
        let model = hand(HandParams { side, ..HandParams::default() });
        let appearance = model.appearance.as_ref().unwrap();
        let [back, _] = appearance.maps();
        let albedo = &back.albedo;
        let positions = model.mesh.positions();
        let world = model.skeleton.rest_world();
        // Red less blue: a pink nail bed is bluer than skin.
        let redness = |uv: [f32; 2]| {
            let (x, y) = ((uv[0] * albedo.width as f32) as usize, (uv[1] * albedo.height as f32) as usize);
            let p = &albedo.rgb[3 * (y * albedo.width as usize + x)..][..3];
            f32::from(p[0]) - f32::from(p[2])
        };
        let range = |r: SurfaceRegion| appearance.regions.iter().find(|x| x.0 == r).unwrap().1.clone();
        for finger in webxr::FINGERS {
            let distal = joint(&format!("{finger}-phalanx-distal"));
            let (start, tip) = (Vec3::from(world[distal].translation), Vec3::from(world[distal + 1].translation));
            // This finger's nail vertices, and the back's over its middle phalanx (the thumb's
            // proximal one).
            let near = |r: SurfaceRegion, centre: Vec3, within: f32| -> Vec<[f32; 2]> {
                model.mesh.indices()[range(r)].iter().filter(|&&v| Vec3::from(positions[v as usize]).distance(centre) < within).map(|&v| model.mesh.uvs()[v as usize]).collect()
            };
            let nail = near(SurfaceRegion::Nail, start.lerp(tip, 0.55), 0.6 * start.distance(tip));
            let skin = near(SurfaceRegion::Back, start.lerp(Vec3::from(world[distal - 1].translation), 0.5), 0.6 * start.distance(tip));
            assert!(!nail.is_empty() && !skin.is_empty(), "{side:?} {finger}: vertices");
            let mean = |uvs: &[[f32; 2]]| uvs.iter().map(|&uv| redness(uv)).sum::<f32>() / uvs.len() as f32;
            let (nail, skin) = (mean(&nail), mean(&skin));
            assert!(nail < skin - 10.0, "{side:?} {finger}: the nail's red less blue is {nail:.0}, the skin's behind it {skin:.0}");
        }
    }
}

#[test]
fn the_glb_has_a_primitive_per_region_over_the_same_vertices() {
    let model = hand(HandParams { vertices: 3_000, ..HandParams::default() });
    let bytes = dqhand::io::skinned_glb(&model);
    let doc = gltf::Gltf::from_slice(&bytes).expect("the GLB parses");
    let mesh = doc.meshes().next().unwrap();
    let names: Vec<&str> = mesh.primitives().map(|p| p.material().name().unwrap_or("")).collect();
    assert_eq!(names, ["skin-back", "skin-palm", "nail"]);
    // Every region in its side's maps, the nails (on the back's) glossier than the skin.
    let materials: Vec<gltf::Material> = mesh.primitives().map(|p| p.material()).collect();
    let albedo = |m: &gltf::Material| m.pbr_metallic_roughness().base_color_texture().map(|t| t.texture().source().index());
    assert!(materials.iter().all(|m| albedo(m).is_some() && m.normal_texture().is_some()));
    assert_eq!(albedo(&materials[2]), albedo(&materials[0]));
    assert_ne!(albedo(&materials[1]), albedo(&materials[0]));
    assert!(materials[2].pbr_metallic_roughness().roughness_factor() < materials[0].pbr_metallic_roughness().roughness_factor());
    let positions: Vec<usize> = mesh.primitives().map(|p| p.get(&gltf::Semantic::Positions).unwrap().index()).collect();
    assert!(positions.windows(2).all(|w| w[0] == w[1]), "one POSITION accessor for all: {positions:?}");
    assert_eq!(doc.images().count(), 4);
    assert!(doc.images().all(|i| matches!(i.source(), gltf::image::Source::View { mime_type: "image/png", .. })));
    // Read back: the same vertices, the same triangles in the same order.
    let path = std::env::temp_dir().join(format!("dqhand-appearance-{}.glb", std::process::id()));
    std::fs::write(&path, &bytes).unwrap();
    let back = dqhand::io::load_gltf(&path).unwrap();
    std::fs::remove_file(&path).ok();
    assert_eq!(back.mesh.vertex_count(), model.mesh.vertex_count());
    assert_eq!(back.mesh.indices(), model.mesh.indices());
    assert_eq!(back.mesh.parts().len(), 3);
}

#[test]
fn a_sparse_and_a_dense_hand_keep_their_regions_whole() {
    for vertices in [1_000, 20_000] {
        let model = hand(HandParams { vertices, ..HandParams::default() });
        let appearance = model.appearance.as_ref().unwrap();
        assert!(appearance.covers(model.mesh.indices().len()), "{vertices}: {:?}", appearance.regions);
        let nails = appearance.regions.iter().find(|r| r.0 == SurfaceRegion::Nail).unwrap().1.len() / 3;
        assert!(nails > 0, "{vertices} vertices: no nail triangles");
        let bytes = dqhand::io::skinned_glb(&model);
        let doc = gltf::Gltf::from_slice(&bytes).expect("the GLB parses");
        assert_eq!(doc.meshes().next().unwrap().primitives().count(), 3);
    }
}
