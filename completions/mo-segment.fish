complete -c mo-segment -l k -d 'Clusters (kinds of action) to find; segments with the same label are the same kind' -r
complete -c mo-segment -l pca-dims -d 'Principal components kept (0 = cluster the features as they are)' -r
complete -c mo-segment -l window -d 'Temporal context: mean and std of each component over this many seconds around a frame (0 = single frames)' -r
complete -c mo-segment -l min-segment -d 'Shortest segment in frames; shorter runs are merged into their longer neighbour' -r
complete -c mo-segment -l features -d 'What each frame is described by' -r -f -a "raw\t'The motion\'s own AnyTop features without the root\'s facing (a baseline; no model needed)'
dift\t'Diffusion features (AnyTop §5: the denoiser\'s activations, averaged over joints), as `mo-dift` computes them'"
complete -c mo-segment -l model -d 'With --features dift: model directory written by mo-train [default: the built-in model]' -r -F
complete -c mo-segment -l t -d 'With --features dift: diffusion step the motion is noised to' -r
complete -c mo-segment -l layer -d 'With --features dift: layer whose activations are read (0-based)' -r
complete -c mo-segment -l draws -d 'With --features dift: noise draws averaged' -r
complete -c mo-segment -l restarts -d 'K-means restarts from different seedings; the tightest clustering wins' -r
complete -c mo-segment -l skeleton -d 'The input\'s skeleton, a skeleton document (skel-info) or a BVH file: a BVH input is encoded with its AnyTop record (as \'mo-encode --skeleton\' does), an NPY input is checked against it' -r -F
complete -c mo-segment -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c mo-segment -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c mo-segment -l threads -d 'Worker threads (default: all cores; at most 256). Output never depends on this' -r
complete -c mo-segment -l animation -d 'glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first)' -r
complete -c mo-segment -l fps -d 'glTF inputs: sample the animation at this frame rate (default: at its keyframe times)' -r
complete -c mo-segment -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c mo-segment -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c mo-segment -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mo-segment -s V -l version -d 'Print version'
