//! A skin and one animation of a glTF file as our skeleton and motion (see the module docs for
//! the rules). Everything the crate does not check and we index with is checked here first, so
//! no file can make us panic.

use super::sample::{Interpolation, Track};
use super::{AnimationChoice, GltfError, ReadOptions};
use crate::bvh::Channel;
use crate::motion::Motion;
use crate::skeleton::{Joint, Skeleton};
use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::animation::Property;
use ::gltf::{Accessor, Document, Gltf};
use base64::Engine as _;
use glam::{DMat4, DQuat, DVec3, DVec4};
use std::borrow::Cow;
use std::collections::{BTreeSet, HashMap};
use std::path::Path;

/// A file we should read as glTF: GLB's magic, or a `.gltf`/`.glb` name.
pub fn looks_like_gltf(path: &Path, bytes: &[u8]) -> bool {
    bytes.starts_with(b"glTF") || path.extension().is_some_and(|x| x.eq_ignore_ascii_case("gltf") || x.eq_ignore_ascii_case("glb"))
}

/// Read the skeleton and motion of a glTF or GLB file. `base_dir` is where a `.gltf`'s external
/// buffers live (`None` for stdin: such files must embed their buffers).
pub fn read(bytes: &[u8], name: &str, base_dir: Option<&Path>, options: &ReadOptions) -> Result<(Skeleton, Motion), GltfError> {
    let file = Reader { name };
    let gltf = Gltf::from_slice(bytes).map_err(|e| file.parse_error(e))?;
    let buffers = file.buffers(&gltf, base_dir)?;
    file.skeleton_and_motion(&gltf.document, &buffers, options)
}

/// The file's name, for messages.
struct Reader<'a> {
    name: &'a str,
}

/// A skin joint before ordering: its node and its parent's position in the skin's list.
struct SkinJoint {
    node: usize,
    parent: Option<usize>,
}

/// The animated tracks of one joint.
#[derive(Default)]
struct JointTracks {
    rotation: Option<Track>,
    translation: Option<Track>,
}

impl Reader<'_> {
    fn data(&self, message: impl Into<String>) -> GltfError {
        GltfError::Data { file: self.name.to_string(), message: message.into() }
    }

    fn parse_error(&self, e: ::gltf::Error) -> GltfError {
        let message = match e {
            ::gltf::Error::Validation(errors) => {
                let more = if errors.len() > 1 { format!(" (and {} more)", errors.len() - 1) } else { String::new() };
                match errors.first() {
                    Some((path, error)) => format!("invalid glTF: {path}: {error}{more}"),
                    None => "invalid glTF".to_string(),
                }
            }
            other => format!("not a readable glTF file: {other}"),
        };
        GltfError::Parse { file: self.name.to_string(), message }
    }

    /// The bytes of every buffer: the GLB binary chunk, a base64 `data:` URI, or a file beside
    /// the `.gltf`. Each must hold at least the length the file declares.
    fn buffers<'g>(&self, gltf: &'g Gltf, base_dir: Option<&Path>) -> Result<Vec<Cow<'g, [u8]>>, GltfError> {
        let mut out = Vec::new();
        for buffer in gltf.document.buffers() {
            let i = buffer.index();
            let bytes: Cow<[u8]> = match buffer.source() {
                ::gltf::buffer::Source::Bin => match gltf.blob.as_deref() {
                    Some(blob) => Cow::Borrowed(blob),
                    None => return Err(self.data(format!("buffer {i} is the GLB binary chunk, but the file has none"))),
                },
                ::gltf::buffer::Source::Uri(uri) => Cow::Owned(self.uri_bytes(i, uri, base_dir)?),
            };
            if bytes.len() < buffer.length() {
                return Err(self.data(format!("buffer {i} holds {} bytes but the file says {}", bytes.len(), buffer.length())));
            }
            out.push(bytes);
        }
        Ok(out)
    }

    fn uri_bytes(&self, i: usize, uri: &str, base_dir: Option<&Path>) -> Result<Vec<u8>, GltfError> {
        if let Some(rest) = uri.strip_prefix("data:") {
            let Some((_, encoded)) = rest.split_once(";base64,") else {
                return Err(self.data(format!("buffer {i}: a data: URI must be base64")));
            };
            return base64::engine::general_purpose::STANDARD.decode(encoded).map_err(|e| self.data(format!("buffer {i}: bad base64 in its data: URI: {e}")));
        }
        if uri.contains("://") {
            return Err(self.data(format!("buffer {i}: '{uri}' is not a local file")));
        }
        let Some(dir) = base_dir else {
            return Err(self.data(format!("buffer {i} is the file '{uri}', which cannot be found from stdin: give the .gltf as a file, or a .glb")));
        };
        let path = dir.join(uri);
        std::fs::read(&path).map_err(|source| GltfError::Io { file: format!("{} (buffer {i}, {})", self.name, path.display()), source })
    }

    fn skeleton_and_motion(&self, doc: &Document, buffers: &[Cow<[u8]>], options: &ReadOptions) -> Result<(Skeleton, Motion), GltfError> {
        let Some(skin) = doc.skins().next() else {
            return Err(self.data("no skin: expected a skinned armature (a skin whose joints are the skeleton)"));
        };
        let parents = self.node_parents(doc)?;
        let skin_joints = self.skin_joints(doc, &skin, &parents)?;
        let order = parent_first_order(&skin_joints);
        // Position in `order` of each skin entry, and of each joint node.
        let mut at = vec![0; order.len()];
        for (k, &s) in order.iter().enumerate() {
            at[s] = k;
        }
        let joint_of_node: HashMap<usize, usize> = order.iter().enumerate().map(|(k, &s)| (skin_joints[s].node, k)).collect();
        let nodes: Vec<::gltf::Node> = doc.nodes().collect();

        let root_node = skin_joints[order[0]].node;
        let (scale, above_rotation, above_translation) = self.above_root(&nodes, &parents, root_node)?;

        // Rest transforms and names, in our order.
        let mut rest_rotation = Vec::with_capacity(order.len());
        let mut joints = Vec::with_capacity(order.len());
        for &s in &order {
            let node = &nodes[skin_joints[s].node];
            let (t, r, sc) = node.transform().decomposed();
            let name = joint_name(node.name(), joints.len());
            if sc.iter().any(|&v| !((f64::from(v) - 1.0).abs() <= 1e-5)) {
                return Err(self.data(format!("joint '{name}' has scale {sc:?}: scaled joints are not supported")));
            }
            let offset = DVec3::from_array(t.map(f64::from)) * scale;
            let rotation = self.unit_quat(r, &name)?;
            if !offset.is_finite() {
                return Err(self.data(format!("joint '{name}' has a non-finite translation")));
            }
            let end_sites = node
                .children()
                .filter(|c| {
                    !joint_of_node.contains_key(&c.index()) && c.children().next().is_none() && c.mesh().is_none() && c.skin().is_none() && c.camera().is_none()
                })
                .map(|c| DVec3::from_array(c.transform().decomposed().0.map(f64::from)) * scale)
                .filter(|e| e.is_finite())
                .collect();
            rest_rotation.push(rotation);
            joints.push(Joint { name, parent: skin_joints[s].parent.map(|p| at[p]), offset, channels: Vec::new(), end_sites });
        }

        let tracks = self.animation_tracks(doc, buffers, options, &joint_of_node, &joints)?;
        let (times, frame_time) = self.frame_times(&tracks, options)?;
        crate::budget::check_motion("the glTF animation", times.len(), joints.len()).map_err(|e| self.data(e.to_string()))?;

        let nj = joints.len();
        let mut rotations = Vec::with_capacity(times.len() * nj);
        let mut translations = Vec::with_capacity(times.len() * nj);
        for &t in &times {
            for (j, joint) in joints.iter().enumerate() {
                let mut r = tracks[j].rotation.as_ref().map_or(rest_rotation[j], |tr| tr.quat_at(t));
                let mut p = tracks[j].translation.as_ref().map_or(joint.offset, |tr| tr.vec3_at(t) * scale);
                if j == 0 {
                    r = above_rotation * r;
                    p = above_translation + above_rotation * p;
                }
                rotations.push(r);
                translations.push(p);
            }
        }
        // Exporters (Blender) key every bone's translation, at its rest value up to float32
        // noise (up to 1.2e-6 of the bone in Blender 3.4's): such a joint does not translate,
        // and keeps the 3 rotation channels in BVH. Real motion that small is lost (5e-6 of
        // height moved 1.05e-5 on a Truebones chicken, whose joints all carry positions).
        let frames = times.len();
        let bone = joints.iter().map(|j| j.offset.length()).sum::<f64>() / nj as f64;
        let mut moves = vec![false; nj];
        for (j, joint) in joints.iter().enumerate().skip(1) {
            let tol = 2e-6 * joint.offset.length().max(bone);
            moves[j] = (0..frames).any(|f| translations[f * nj + j].distance(joint.offset) > tol);
            if !moves[j] {
                for f in 0..frames {
                    translations[f * nj + j] = joint.offset;
                }
            }
        }
        let motion = Motion { frames, joints: nj, frame_time, rotations, translations };
        if let Some((f, j)) = motion.first_non_finite() {
            return Err(self.data(format!("frame {f}, joint '{}': the animation gives a non-finite pose", joints[j].name)));
        }

        // Channels, for writing BVH: the root and any joint whose translation moves off its
        // offset carry positions (a BVH position channel replaces the OFFSET).
        for (j, joint) in joints.iter_mut().enumerate() {
            if j == 0 || moves[j] {
                joint.channels.extend([Channel::Xposition, Channel::Yposition, Channel::Zposition]);
            }
            joint.channels.extend([Channel::Zrotation, Channel::Xrotation, Channel::Yrotation]);
        }
        let skeleton = Skeleton { joints, frame_time };
        skeleton.validate().map_err(|e| self.data(e.to_string()))?;
        Ok((skeleton, motion))
    }

    /// Each node's parent, refusing nodes with two parents and cycles.
    fn node_parents(&self, doc: &Document) -> Result<Vec<Option<usize>>, GltfError> {
        let n = doc.nodes().len();
        let mut parents = vec![None; n];
        for node in doc.nodes() {
            for child in node.children() {
                let c = child.index();
                if c == node.index() || parents[c].is_some() {
                    return Err(self.data(format!("node {c} has more than one parent: the node hierarchy must be a tree")));
                }
                parents[c] = Some(node.index());
            }
        }
        // A cycle shows as a walk up that never ends.
        for start in 0..n {
            let mut at = start;
            let mut steps = 0;
            while let Some(p) = parents[at] {
                at = p;
                steps += 1;
                if steps > n {
                    return Err(self.data("the node hierarchy has a cycle"));
                }
            }
        }
        Ok(parents)
    }

    /// The skin's joints with their parent joints; exactly one root, and every other joint's
    /// parent node must itself be a joint (we cannot carry an unskinned node's rotation).
    fn skin_joints(&self, doc: &Document, skin: &::gltf::Skin, parents: &[Option<usize>]) -> Result<Vec<SkinJoint>, GltfError> {
        let nodes: Vec<usize> = skin.joints().map(|n| n.index()).collect();
        if nodes.is_empty() {
            return Err(self.data("the skin has no joints"));
        }
        let position: HashMap<usize, usize> = nodes.iter().enumerate().map(|(k, &n)| (n, k)).collect();
        if position.len() != nodes.len() {
            return Err(self.data("the skin lists a joint twice"));
        }
        let node_name = |n: usize| doc.nodes().nth(n).and_then(|x| x.name().map(str::to_string)).unwrap_or_else(|| format!("node {n}"));
        let mut roots = Vec::new();
        let mut out = Vec::with_capacity(nodes.len());
        for &n in &nodes {
            let parent = match parents[n] {
                Some(p) if position.contains_key(&p) => Some(position[&p]),
                Some(p) => {
                    let mut up = parents[p];
                    while let Some(a) = up {
                        if position.contains_key(&a) {
                            return Err(self.data(format!(
                                "joint '{}' hangs under '{}', which is not a joint of the skin: every joint's parent must be a joint or above the root",
                                node_name(n),
                                node_name(p)
                            )));
                        }
                        up = parents[a];
                    }
                    None
                }
                None => None,
            };
            if parent.is_none() {
                roots.push(node_name(n));
            }
            out.push(SkinJoint { node: n, parent });
        }
        if roots.len() != 1 {
            let shown: Vec<String> = roots.iter().take(5).map(|r| format!("'{r}'")).collect();
            return Err(self.data(format!("the skin has {} root joints ({}): one root is supported", roots.len(), shown.join(", "))));
        }
        Ok(out)
    }

    /// The transform of the nodes above the root joint (an armature object), as a uniform
    /// scale, a rotation and a translation.
    fn above_root(&self, nodes: &[::gltf::Node], parents: &[Option<usize>], root: usize) -> Result<(f64, DQuat, DVec3), GltfError> {
        let mut m = DMat4::IDENTITY;
        let mut up = parents[root];
        while let Some(p) = up {
            let cols = nodes[p].transform().matrix().map(|c| c.map(f64::from));
            m = DMat4::from_cols_array_2d(&cols) * m;
            up = parents[p];
        }
        if m == DMat4::IDENTITY {
            return Ok((1.0, DQuat::IDENTITY, DVec3::ZERO));
        }
        let (s, r, t) = m.to_scale_rotation_translation();
        let uniform = s.x > 0.0 && (s.y - s.x).abs() <= 1e-5 * s.x && (s.z - s.x).abs() <= 1e-5 * s.x && m.determinant() > 0.0;
        if !uniform || !s.is_finite() || !r.is_finite() || !t.is_finite() {
            return Err(self.data(format!("the nodes above the root joint scale it by {:?}: only a uniform positive scale is supported", s.to_array())));
        }
        Ok((s.x, r.normalize(), t))
    }

    fn unit_quat(&self, r: [f32; 4], what: &str) -> Result<DQuat, GltfError> {
        let q = DQuat::from_array(r.map(f64::from));
        if !q.is_finite() || q.length() < 1e-6 {
            return Err(self.data(format!("joint '{what}' has a rotation {r:?} that is not a rotation")));
        }
        Ok(q.normalize())
    }

    /// The chosen animation's rotation and translation tracks of each joint (our order).
    fn animation_tracks(
        &self,
        doc: &Document,
        buffers: &[Cow<[u8]>],
        options: &ReadOptions,
        joint_of_node: &HashMap<usize, usize>,
        joints: &[Joint],
    ) -> Result<Vec<JointTracks>, GltfError> {
        let mut tracks: Vec<JointTracks> = (0..joints.len()).map(|_| JointTracks::default()).collect();
        let Some(animation) = self.choose_animation(doc, &options.animation)? else { return Ok(tracks) };
        let label = animation.name().map_or_else(|| format!("animation {}", animation.index()), |n| format!("animation '{n}'"));
        self.check_channel_targets(doc, animation.index(), &label)?;
        for channel in animation.channels() {
            let Some(&j) = joint_of_node.get(&channel.target().node().index()) else { continue };
            let joint = &joints[j].name;
            let sampler = channel.sampler();
            let interpolation = match sampler.interpolation() {
                ::gltf::animation::Interpolation::Linear => Interpolation::Linear,
                ::gltf::animation::Interpolation::Step => Interpolation::Step,
                ::gltf::animation::Interpolation::CubicSpline => Interpolation::CubicSpline,
            };
            let what = |p: &str| format!("{label}, {p} of joint '{joint}'");
            let property = channel.target().property();
            let (dims, name) = match property {
                Property::Rotation => (Dimensions::Vec4, "rotation"),
                Property::Translation => (Dimensions::Vec3, "translation"),
                Property::Scale => (Dimensions::Vec3, "scale"),
                Property::MorphTargetWeights => continue,
            };
            let input = sampler.input();
            let output = sampler.output();
            self.check_accessor(&input, &[DataType::F32], Dimensions::Scalar, &what(name), buffers)?;
            let types: &[DataType] =
                if property == Property::Rotation { &[DataType::F32, DataType::I8, DataType::U8, DataType::I16, DataType::U16] } else { &[DataType::F32] };
            self.check_accessor(&output, types, dims, &what(name), buffers)?;
            let per_key = if interpolation == Interpolation::CubicSpline { 3 } else { 1 };
            if output.count() != input.count() * per_key {
                return Err(self.data(format!("{}: {} keys but {} values", what(name), input.count(), output.count())));
            }
            let reader = channel.reader(|b| buffers.get(b.index()).map(|c| &c[..]));
            let times: Vec<f64> = match reader.read_inputs() {
                Some(iter) => iter.map(f64::from).collect(),
                None => Vec::new(),
            };
            let values: Vec<DVec4> = match reader.read_outputs() {
                Some(::gltf::animation::util::ReadOutputs::Rotations(r)) => r.into_f32().map(|v| DVec4::from_array(v.map(f64::from))).collect(),
                Some(::gltf::animation::util::ReadOutputs::Translations(t)) => t.map(|v| DVec3::from_array(v.map(f64::from)).extend(0.0)).collect(),
                Some(::gltf::animation::util::ReadOutputs::Scales(t)) => t.map(|v| DVec3::from_array(v.map(f64::from)).extend(0.0)).collect(),
                _ => Vec::new(),
            };
            if times.len() != input.count() || values.len() != output.count() {
                return Err(self.data(format!("{}: the keys run past the end of their buffer", what(name))));
            }
            if times.iter().any(|t| !t.is_finite()) || times.windows(2).any(|w| !(w[1] > w[0])) {
                return Err(self.data(format!("{}: key times must be finite and increasing", what(name))));
            }
            if values.iter().any(|v| !v.is_finite()) {
                return Err(self.data(format!("{}: a key holds a non-finite value", what(name))));
            }
            let mut track = Track { times, values, interpolation };
            match property {
                Property::Rotation => {
                    for v in &mut track.values {
                        *v = v.try_normalize().unwrap_or(DVec4::W);
                    }
                    tracks[j].rotation = Some(track);
                }
                Property::Translation => tracks[j].translation = Some(track),
                _ => {
                    if !track.all_keys_near(DVec4::new(1.0, 1.0, 1.0, 0.0), 1e-5) {
                        return Err(self.data(format!("{}: scale animation is not supported (keys other than 1)", what(name))));
                    }
                }
            }
        }
        Ok(tracks)
    }

    /// The crate validates samplers but not channel targets, whose accessors would panic on a
    /// bad node index or an unknown path: check them in the JSON first.
    fn check_channel_targets(&self, doc: &Document, animation: usize, label: &str) -> Result<(), GltfError> {
        use ::gltf::json::validation::Checked;
        let root = doc.as_json();
        let Some(json) = root.animations.get(animation) else { return Ok(()) };
        for (k, channel) in json.channels.iter().enumerate() {
            if channel.target.node.value() >= root.nodes.len() {
                return Err(self.data(format!("{label}: channel {k} targets node {}, which does not exist", channel.target.node.value())));
            }
            if matches!(channel.target.path, Checked::Invalid) {
                return Err(self.data(format!("{label}: channel {k} animates an unknown property")));
            }
        }
        Ok(())
    }

    fn choose_animation<'d>(&self, doc: &'d Document, choice: &AnimationChoice) -> Result<Option<::gltf::Animation<'d>>, GltfError> {
        let names = || {
            let all: Vec<String> = doc.animations().take(10).map(|a| a.name().map_or_else(|| format!("#{}", a.index()), |n| format!("'{n}'"))).collect();
            if all.is_empty() {
                "it has none".to_string()
            } else {
                format!("it has {}", all.join(", "))
            }
        };
        match choice {
            AnimationChoice::First => Ok(doc.animations().next()),
            AnimationChoice::Index(i) => match doc.animations().nth(*i) {
                Some(a) => Ok(Some(a)),
                None => Err(self.data(format!("no animation {i} ({}; counted from 0)", names()))),
            },
            AnimationChoice::Name(n) => match doc.animations().find(|a| a.name() == Some(n.as_str())) {
                Some(a) => Ok(Some(a)),
                None => Err(self.data(format!("no animation named '{n}' ({})", names()))),
            },
        }
    }

    /// What the crate's reader assumes of an accessor and does not check itself.
    fn check_accessor(&self, accessor: &Accessor, types: &[DataType], dims: Dimensions, what: &str, buffers: &[Cow<[u8]>]) -> Result<(), GltfError> {
        if accessor.count() == 0 {
            return Err(self.data(format!("{what}: no keys")));
        }
        if accessor.sparse().is_some() || accessor.view().is_none() {
            return Err(self.data(format!("{what}: sparse or buffer-less accessors are not supported")));
        }
        if !types.contains(&accessor.data_type()) || accessor.dimensions() != dims {
            return Err(self.data(format!(
                "{what}: accessor {} is {:?} {:?}, expected {dims:?} of {types:?}",
                accessor.index(),
                accessor.dimensions(),
                accessor.data_type()
            )));
        }
        // The crate computes offset + stride * (count - 1) unchecked (and debug-asserts the
        // stride): keep every term far from overflow and the stride at least an element.
        let element = accessor.size();
        if let Some(view) = accessor.view() {
            let stride = view.stride().unwrap_or(element);
            if stride < element {
                return Err(self.data(format!("{what}: accessor {} has a stride smaller than its elements", accessor.index())));
            }
            let data = buffers.get(view.buffer().index()).map_or(0, |b| b.len());
            let view_fits = view.offset().checked_add(view.length()).is_some_and(|end| end <= data);
            if !view_fits || accessor.count() > view.length() || accessor.offset() > view.length() {
                return Err(self.data(format!("{what}: accessor {} reaches past its buffer", accessor.index())));
            }
        }
        Ok(())
    }

    /// Frame times: the union of the key times when evenly spaced, else a grid at the smallest
    /// key interval; or a grid at `options.fps`. One frame when nothing is animated.
    fn frame_times(&self, tracks: &[JointTracks], options: &ReadOptions) -> Result<(Vec<f64>, f64), GltfError> {
        let mut keys = BTreeSet::new();
        for t in tracks {
            for track in [&t.rotation, &t.translation].into_iter().flatten() {
                keys.extend(track.times.iter().map(|&x| x.to_bits()));
            }
        }
        // Non-negative finite f64 order as their bits; negative times sort apart, so sort values.
        let mut keys: Vec<f64> = keys.into_iter().map(f64::from_bits).collect();
        keys.sort_by(f64::total_cmp);
        let default_time = options.fps.map_or(1.0 / 30.0, |f| 1.0 / f);
        let (Some(&first), Some(&last)) = (keys.first(), keys.last()) else { return Ok((vec![0.0], default_time)) };
        if keys.len() == 1 {
            return Ok((vec![first], default_time));
        }
        let (step, from_keys) = match options.fps {
            Some(fps) => (1.0 / fps, false),
            None => {
                let even = (last - first) / (keys.len() - 1) as f64;
                if keys.iter().enumerate().all(|(i, &t)| (t - (first + i as f64 * even)).abs() <= 1e-3 * even) {
                    (even, true)
                } else {
                    (keys.windows(2).map(|w| w[1] - w[0]).fold(f64::INFINITY, f64::min), false)
                }
            }
        };
        // Key times are float32: a last key a hair before a whole step still counts as that step.
        let frames = ((last - first) / step + 1e-4).floor() + 1.0;
        if !(frames <= options.max_frames as f64) {
            return Err(self.data(format!(
                "the animation lasts {:.3} s: {frames:.0} frames at {:.3} fps, more than the {} a motion may have",
                last - first,
                1.0 / step,
                options.max_frames
            )));
        }
        let times = if from_keys { keys } else { (0..frames as usize).map(|i| first + i as f64 * step).collect() };
        let frame_time = if options.fps.is_some() { step } else { frame_time_of_keys(step) };
        Ok((times, frame_time))
    }
}

/// Skin entries ordered parents first, otherwise in the skin's order.
fn parent_first_order(joints: &[SkinJoint]) -> Vec<usize> {
    let mut children = vec![Vec::new(); joints.len()];
    let mut ready = BTreeSet::new();
    for (k, j) in joints.iter().enumerate() {
        match j.parent {
            Some(p) => children[p].push(k),
            None => {
                ready.insert(k);
            }
        }
    }
    let mut order = Vec::with_capacity(joints.len());
    while let Some(k) = ready.pop_first() {
        order.push(k);
        ready.extend(children[k].iter().copied());
    }
    order
}

/// A usable joint name: the node's, without the line breaks and tabs a BVH line cannot hold.
fn joint_name(name: Option<&str>, k: usize) -> String {
    let clean: String = name.unwrap_or("").trim().chars().map(|c| if c.is_control() { '_' } else { c }).collect();
    if clean.is_empty() {
        format!("joint{k}")
    } else {
        clean
    }
}

/// A frame time read back from f32 key times: 1/N seconds when it is that within f32 precision
/// (1/30 comes back as 1/30), else the shortest decimal within it, so a BVH's `Frame Time:
/// 0.0333333` comes back as written rather than as 0.03333333134651184.
fn frame_time_of_keys(step: f64) -> f64 {
    let per_second = (1.0 / step).round();
    if per_second >= 1.0 && (1.0 / per_second - step).abs() <= 1.5e-7 * step {
        return 1.0 / per_second;
    }
    for digits in 1..=17 {
        let scale = 10f64.powi(digits);
        let rounded = (step * scale).round() / scale;
        if rounded > 0.0 && (rounded - step).abs() <= 3e-7 * step {
            return rounded;
        }
    }
    step
}
