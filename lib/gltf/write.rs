//! Our skeleton and motion as a glTF file (GLB, or `.gltf` JSON with the buffer inlined as a
//! base64 `data:` URI so it stays one file), built with `gltf-json`.
//!
//! Layout: nodes 0..J are the joints in skeleton order (so a skin joint's index is our joint
//! index), then one node per End Site, then the mesh node; rest rotations are identity, which
//! is what our rest pose means, so the inverse bind matrices are plain translations. Key times
//! are `frame * frame_time`; every joint gets a rotation channel, the root and every joint whose
//! translation moves get a translation channel. Output depends only on the input.

use super::mesh::{self, Sticks};
use super::GltfError;
use crate::motion::Motion;
use crate::skeleton::Skeleton;
use base64::Engine as _;
use glam::DVec3;
use gltf_json as json;
use json::validation::{Checked::Valid, USize64};
use json::Index;

/// A GLB file of `motion` on `skeleton`; `name` is the file's, for messages.
pub fn write_glb(skeleton: &Skeleton, motion: &Motion, name: &str) -> Result<Vec<u8>, GltfError> {
    let (root, bin) = build(skeleton, motion);
    let json = json::serialize::to_vec(&root).map_err(|e| data(name, format!("cannot serialise the glTF: {e}")))?;
    let glb = ::gltf::binary::Glb {
        header: ::gltf::binary::Header { magic: *b"glTF", version: 2, length: 0 },
        json: json.into(),
        bin: (!bin.is_empty()).then_some(bin.into()),
    };
    // The crate computes the length; it refuses files past GLB's 4 GiB.
    let total = 12 + 8 + glb.json.len() + 8 + glb.bin.as_ref().map_or(0, |b| b.len()) + 6;
    if total > u32::MAX as usize {
        return Err(data(name, format!("the motion needs {total} bytes, more than a GLB file can hold (4 GiB)")));
    }
    glb.to_vec().map_err(|e| data(name, format!("cannot build the GLB: {e}")))
}

/// A `.gltf` (JSON) file of `motion` on `skeleton`, its buffer inlined.
pub fn write_gltf(skeleton: &Skeleton, motion: &Motion, name: &str) -> Result<Vec<u8>, GltfError> {
    let (mut root, bin) = build(skeleton, motion);
    if let Some(buffer) = root.buffers.first_mut() {
        buffer.uri = Some(format!("data:application/octet-stream;base64,{}", base64::engine::general_purpose::STANDARD.encode(&bin)));
    }
    let mut text = json::serialize::to_vec_pretty(&root).map_err(|e| data(name, format!("cannot serialise the glTF: {e}")))?;
    text.push(b'\n');
    Ok(text)
}

fn data(name: &str, message: String) -> GltfError {
    GltfError::Data { file: name.to_string(), message }
}

/// The glTF document and its one binary buffer.
fn build(skeleton: &Skeleton, motion: &Motion) -> (json::Root, Vec<u8>) {
    let mut b = Builder::default();
    let nj = skeleton.joints.len();
    let rest: Vec<DVec3> = crate::motion::Motion::rest(skeleton).forward_kinematics(skeleton).positions;

    // Joint nodes, then End Site nodes.
    let mut children: Vec<Vec<Index<json::Node>>> = vec![Vec::new(); nj];
    for (j, joint) in skeleton.joints.iter().enumerate().skip(1) {
        if let Some(p) = joint.parent {
            children[p].push(Index::new(j as u32));
        }
    }
    let mut end_nodes = Vec::new();
    for (j, joint) in skeleton.joints.iter().enumerate() {
        for (k, e) in joint.end_sites.iter().enumerate() {
            let suffix = if k == 0 { String::new() } else { (k + 1).to_string() };
            children[j].push(Index::new((nj + end_nodes.len()) as u32));
            end_nodes.push(json::Node { name: Some(format!("{}_end{suffix}", joint.name)), translation: Some(f32x3(*e)), ..Default::default() });
        }
    }
    for (j, joint) in skeleton.joints.iter().enumerate() {
        let kids = std::mem::take(&mut children[j]);
        b.root.nodes.push(json::Node {
            name: Some(joint.name.clone()),
            translation: Some(f32x3(joint.offset)),
            children: (!kids.is_empty()).then_some(kids),
            ..Default::default()
        });
    }
    b.root.nodes.extend(end_nodes);

    // The skin: inverse bind matrices undo each joint's rest position (rest rotations are identity).
    let mut ibm = Vec::with_capacity(nj * 64);
    for p in &rest {
        let m = glam::DMat4::from_translation(-*p).to_cols_array();
        for v in m {
            ibm.extend((v as f32).to_le_bytes());
        }
    }
    let ibm_accessor = b.accessor(&ibm, nj, json::accessor::ComponentType::F32, json::accessor::Type::Mat4, None, None);
    b.root.skins.push(json::Skin {
        extensions: None,
        extras: Default::default(),
        inverse_bind_matrices: Some(ibm_accessor),
        joints: (0..nj as u32).map(Index::new).collect(),
        name: Some("skeleton".to_string()),
        skeleton: Some(Index::new(0)),
    });

    let mut scene_nodes = vec![Index::new(0)];
    if let Some(sticks) = mesh::sticks(skeleton, motion, &rest) {
        let mesh = b.sticks_mesh(&sticks);
        scene_nodes.push(Index::new(b.root.nodes.len() as u32));
        b.root.nodes.push(json::Node { name: Some("body".to_string()), mesh: Some(mesh), skin: Some(Index::new(0)), ..Default::default() });
    }
    b.root.scenes.push(json::Scene { extensions: None, extras: Default::default(), name: None, nodes: scene_nodes });
    b.root.scene = Some(Index::new(0));

    if motion.frames > 0 {
        b.animation(skeleton, motion);
    }
    b.root.asset = json::Asset { generator: Some(format!("menagerie {}", env!("CARGO_PKG_VERSION"))), ..Default::default() };
    let bin = std::mem::take(&mut b.bin);
    if !bin.is_empty() {
        b.root.buffers.push(json::Buffer { byte_length: USize64(bin.len() as u64), name: None, uri: None, extensions: None, extras: Default::default() });
    }
    (b.root, bin)
}

fn f32x3(v: DVec3) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

#[derive(Default)]
struct Builder {
    root: json::Root,
    bin: Vec<u8>,
}

impl Builder {
    /// One buffer view and accessor over `bytes`, appended to the buffer at a 4-byte boundary.
    fn accessor(
        &mut self,
        bytes: &[u8],
        count: usize,
        component: json::accessor::ComponentType,
        type_: json::accessor::Type,
        bounds: Option<(Vec<f32>, Vec<f32>)>,
        target: Option<json::buffer::Target>,
    ) -> Index<json::Accessor> {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let view = Index::new(self.root.buffer_views.len() as u32);
        self.root.buffer_views.push(json::buffer::View {
            buffer: Index::new(0),
            byte_length: USize64(bytes.len() as u64),
            byte_offset: Some(USize64(self.bin.len() as u64)),
            byte_stride: None,
            name: None,
            target: target.map(Valid),
            extensions: None,
            extras: Default::default(),
        });
        self.bin.extend_from_slice(bytes);
        let (min, max) = match bounds {
            Some((lo, hi)) => (Some(json::Value::from(lo)), Some(json::Value::from(hi))),
            None => (None, None),
        };
        let index = Index::new(self.root.accessors.len() as u32);
        self.root.accessors.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64(count as u64),
            component_type: Valid(json::accessor::GenericComponentType(component)),
            extensions: None,
            extras: Default::default(),
            type_: Valid(type_),
            min,
            max,
            name: None,
            normalized: false,
            sparse: None,
        });
        index
    }

    fn floats(&mut self, values: &[f32], type_: json::accessor::Type, per: usize, bounds: bool) -> Index<json::Accessor> {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let bounds = bounds.then(|| {
            let mut lo = vec![f32::INFINITY; per];
            let mut hi = vec![f32::NEG_INFINITY; per];
            for chunk in values.chunks_exact(per) {
                for (k, &v) in chunk.iter().enumerate() {
                    lo[k] = lo[k].min(v);
                    hi[k] = hi[k].max(v);
                }
            }
            (lo, hi)
        });
        self.accessor(&bytes, values.len() / per, json::accessor::ComponentType::F32, type_, bounds, None)
    }

    fn sticks_mesh(&mut self, sticks: &Sticks) -> Index<json::Mesh> {
        use json::accessor::{ComponentType, Type};
        use json::buffer::Target;
        let n = sticks.positions.len();
        let flat: Vec<f32> = sticks.positions.iter().flatten().copied().collect();
        let positions = {
            let bytes: Vec<u8> = flat.iter().flat_map(|v| v.to_le_bytes()).collect();
            let mut lo = [f32::INFINITY; 3];
            let mut hi = [f32::NEG_INFINITY; 3];
            for p in &sticks.positions {
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
            self.accessor(&bytes, n, ComponentType::F32, Type::Vec3, Some((lo.to_vec(), hi.to_vec())), Some(Target::ArrayBuffer))
        };
        let joints_bytes: Vec<u8> = sticks.joints.iter().flat_map(|&j| [j, 0, 0, 0]).flat_map(u16::to_le_bytes).collect();
        let joints = self.accessor(&joints_bytes, n, ComponentType::U16, Type::Vec4, None, Some(Target::ArrayBuffer));
        let weight_bytes: Vec<u8> = (0..n).flat_map(|_| [1.0f32, 0.0, 0.0, 0.0]).flat_map(f32::to_le_bytes).collect();
        let weights = self.accessor(&weight_bytes, n, ComponentType::F32, Type::Vec4, None, Some(Target::ArrayBuffer));
        let index_bytes: Vec<u8> = sticks.indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        let indices = self.accessor(&index_bytes, sticks.indices.len(), ComponentType::U32, Type::Scalar, None, Some(Target::ElementArrayBuffer));

        let material = Index::new(self.root.materials.len() as u32);
        self.root.materials.push(json::Material { name: Some("bone".to_string()), double_sided: true, ..Default::default() });
        let attributes = [(json::mesh::Semantic::Positions, positions), (json::mesh::Semantic::Joints(0), joints), (json::mesh::Semantic::Weights(0), weights)]
            .into_iter()
            .map(|(s, a)| (Valid(s), a))
            .collect();
        let mesh = Index::new(self.root.meshes.len() as u32);
        self.root.meshes.push(json::Mesh {
            extensions: None,
            extras: Default::default(),
            name: Some("sticks".to_string()),
            primitives: vec![json::mesh::Primitive {
                attributes,
                extensions: None,
                extras: Default::default(),
                indices: Some(indices),
                material: Some(material),
                mode: Valid(json::mesh::Mode::Triangles),
                targets: None,
            }],
            weights: None,
        });
        mesh
    }

    /// One animation: key times, a rotation channel per joint, translation channels where they move.
    fn animation(&mut self, skeleton: &Skeleton, motion: &Motion) {
        use json::animation::{Channel, Interpolation, Property, Sampler, Target};
        let nj = motion.joints;
        let times: Vec<f32> = (0..motion.frames).map(|f| (f as f64 * motion.frame_time) as f32).collect();
        let input = self.floats(&times, json::accessor::Type::Scalar, 1, true);
        let mut samplers = Vec::new();
        let mut channels = Vec::new();
        let mut add = |samplers: &mut Vec<Sampler>, output, node: usize, path| {
            channels.push(Channel {
                sampler: Index::new(samplers.len() as u32),
                target: Target { extensions: None, extras: Default::default(), node: Index::new(node as u32), path: Valid(path) },
                extensions: None,
                extras: Default::default(),
            });
            samplers.push(Sampler { extensions: None, extras: Default::default(), input, interpolation: Valid(Interpolation::Linear), output });
        };
        for (j, joint) in skeleton.joints.iter().enumerate() {
            // Neighbouring keys on the same hemisphere, so viewers' slerp between them takes
            // the short way.
            let mut values = Vec::with_capacity(motion.frames * 4);
            let mut previous: Option<glam::DQuat> = None;
            for f in 0..motion.frames {
                let mut q = motion.rotations[f * nj + j].normalize();
                if previous.is_some_and(|p| p.dot(q) < 0.0) {
                    q = -q;
                }
                previous = Some(q);
                values.extend([q.x as f32, q.y as f32, q.z as f32, q.w as f32]);
            }
            let output = self.floats(&values, json::accessor::Type::Vec4, 4, false);
            add(&mut samplers, output, j, Property::Rotation);

            let moves = j == 0 || (0..motion.frames).any(|f| motion.translations[f * nj + j] != joint.offset);
            if moves {
                let values: Vec<f32> = (0..motion.frames).flat_map(|f| f32x3(motion.translations[f * nj + j])).collect();
                let output = self.floats(&values, json::accessor::Type::Vec3, 3, false);
                add(&mut samplers, output, j, Property::Translation);
            }
        }
        self.root.animations.push(json::Animation { extensions: None, extras: Default::default(), channels, name: Some("motion".to_string()), samplers });
    }
}
