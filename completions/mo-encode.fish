complete -c mo-encode -l repr -d 'Feature representation' -r -f -a "anytop\t'AnyTop: per joint position, 6D rotation, velocity and foot contact; 13 dims, F-1 frames'
m2m\t'Motion2Motion: local 6D rotation of every joint + root position (x/z as velocities); 9 dims'"
complete -c mo-encode -l skeleton -d 'The skeleton: a skeleton document (JSON) or a BVH file (\'-\' = stdin)' -r -F
complete -c mo-encode -l rest-pose -d 'anytop: build the rig on frame 0 of this BVH (same skeleton)' -r -F
complete -c mo-encode -l face-joints -d 'anytop: face joints, four joint names, instead of the automatic choice' -r
complete -c mo-encode -l body-axis -d 'anytop: face along the body, from BACK to FRONT (two joint names)' -r
complete -c mo-encode -l feet -d 'anytop: the joints that get foot-contact labels (joint names) instead of the automatic choice' -r
complete -c mo-encode -l stats -d 'anytop: write the normalisation statistics of the given clips (JSON: mean, std)' -r -F
complete -c mo-encode -l emit-skeleton -d 'anytop: write the skeleton document with the rig used, for decoding' -r -F
complete -c mo-encode -l placement -d 'anytop: where each clip stood (JSON): written when encoding, read when decoding' -r -F
complete -c mo-encode -l from -d 'anytop decoding: from the rotations (default; exact for encoded features) or the positions' -r -f -a "rotations\t'The features\' 6D rotations: exact for encoded features'
positions\t'The features\' joint positions, by inverse kinematics: for generated features'"
complete -c mo-encode -l model -d 'The latent model: a directory from \'mo-train --arch sata\' [default: the built-in one]' -r -F
complete -c mo-encode -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c mo-encode -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c mo-encode -l threads -d 'Worker threads (default: all cores; at most 256). Output never depends on this' -r
complete -c mo-encode -l animation -d 'glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first)' -r
complete -c mo-encode -l fps -d 'glTF inputs: sample the animation at this frame rate (default: at its keyframe times)' -r
complete -c mo-encode -l decode -d 'Decode an NPY of features back to BVH on --skeleton'
complete -c mo-encode -l require-contacts -d 'anytop: fail when the skeleton has no foot joints, instead of writing all-zero contact features with a warning (for training data of walkers, where a missed foot is a bug)'
complete -c mo-encode -l normalise -d 'anytop: write normalised features, (x - mean) / (std + 1e-6)'
complete -c mo-encode -l normalised -d 'anytop decoding: the NPY holds normalised features; undo it with --skeleton\'s statistics'
complete -c mo-encode -l latent -d 'Encode one BVH clip into per-frame latents of the latent model (SATA): NPY [frames - 1, latent], the same size for every skeleton'
complete -c mo-encode -l decode-latent -d 'Decode latents (NPY [frames, latent] from --latent) onto --skeleton, any skeleton, as BVH'
complete -c mo-encode -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c mo-encode -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c mo-encode -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mo-encode -s V -l version -d 'Print version'
