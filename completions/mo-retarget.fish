complete -c mo-retarget -l bind -d 'm2m: binding JSON file, or \'auto\' (required)' -r
complete -c mo-retarget -l method -d 'How to transfer: m2m (Motion2Motion, from example clips and a sparse binding) or latent (zero-shot through the SATA latent model: no examples, no binding)' -r -f -a "m2m\t''
latent\t''"
complete -c mo-retarget -l to -d 'latent: the target skeleton, a BVH or a skeleton document (instead of TARGETS)' -r -F
complete -c mo-retarget -l model -d 'latent: the model directory from \'mo-train --arch sata\' [default: the built-in one]' -r -F
complete -c mo-retarget -l bind-rate -d 'Limit of --bind auto: at most this binding rate, 2 x pairs / (source joints + target joints) (the paper: 0.061) [default: every confident pair]' -r
complete -c mo-retarget -s n -l samples -d 'Number of diverse samples' -r
complete -c mo-retarget -l frames -d 'Output length in frames [default: the source\'s, after resampling]' -r
complete -c mo-retarget -l seconds -d 'Output length in seconds' -r
complete -c mo-retarget -l key-frames -d 'Key-frame mode: the source counts only at these frames (comma-separated, source frames)' -r
complete -c mo-retarget -l format -d 'Output format on stdout: BVH, glTF (glb: binary, gltf: JSON) or Motion2Motion features (npy). An -o file named .glb or .gltf is written as glTF' -r -f -a "bvh\t''
glb\t'Binary glTF (skin, animation, a stick mesh)'
gltf\t'glTF JSON, data inlined'
npy\t'Motion2Motion features [frames, joints, 9]'"
complete -c mo-retarget -l patch -d 'Patch length in frames (paper: 11)' -r
complete -c mo-retarget -l alpha -d 'Weight of the bound (source) channels in matching, 0..1 (paper: 0.85)' -r
complete -c mo-retarget -l steps -d 'Match-and-blend iterations per pyramid level (paper: 3)' -r
complete -c mo-retarget -l pyramid -d 'Scale between pyramid levels (paper: 0.75)' -r
complete -c mo-retarget -l repr -d 'Matching features (paper table 4)' -r -f -a "rotation\t'Local 6D rotations of every joint plus the root\'s dx, y, dz (the paper\'s default)'
velocity\t'World joint velocities (per frame) plus the root\'s dx, y, dz'
position\t'Joint positions relative to the root (translation only) plus the root\'s dx, y, dz'"
complete -c mo-retarget -l bound-rotation -d 'How bound joints take the source\'s rotation' -r -f -a "local\t'The source\'s local rotation, copied as is (the reference\'s behaviour)'
aligned\t'The source\'s local rotation expressed about the target bone: conjugated by the rest rotation that turns the target bone direction onto the source\'s, so a bone that points down the -y axis on one skeleton and along +z on the other still swings the same way'
world\t'The target joint gets the source joint\'s orientation relative to the root (world rotation with the root\'s removed), whatever its parents do'"
complete -c mo-retarget -l root-motion -d 'Where the root trajectory comes from' -r -f -a "examples\t'Synthesised from the examples like any unbound channel (the reference\'s behaviour)'
source\t'The source\'s root trajectory scaled by the ratio of the skeletons\' hip heights; the root position channels are then bound channels'"
complete -c mo-retarget -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c mo-retarget -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c mo-retarget -l threads -d 'Worker threads (default: all cores; at most 256). Output never depends on this' -r
complete -c mo-retarget -l animation -d 'glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first)' -r
complete -c mo-retarget -l fps -d 'glTF inputs: sample the animation at this frame rate (default: at its keyframe times)' -r
complete -c mo-retarget -l emit-binding -d 'Print the binding (JSON) and stop'
complete -c mo-retarget -l copy-bound -d 'After synthesis, overwrite the bound channels with the source\'s (the paper\'s "directly copy", the reference\'s copy mode): bound joints follow the source exactly'
complete -c mo-retarget -l report -d 'Print timing, binding, pyramid levels and per-level match cost on stderr'
complete -c mo-retarget -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c mo-retarget -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c mo-retarget -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mo-retarget -s V -l version -d 'Print version'
