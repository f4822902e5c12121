complete -c mo-dift -l align -d 'With --frames: how frames are matched' -r -f -a "monotonic\t'In time order (dynamic time warping): the answers never go back'
nearest\t'Each target frame on its own: the most similar reference frame (the paper\'s rule)'"
complete -c mo-dift -l bind-rate -d 'With --as-binding: at most this binding rate, 2 x pairs / (REF joints + TGT joints) [default: combined, every confident pair; dift-only, 0.061]' -r
complete -c mo-dift -l features -d 'With --joints: the evidence joints are matched by' -r -f -a "combined\t'The correspondence engine (names, sides, limbs, topology, rest pose); no model runs'
dift-only\t'DIFT features alone (AnyTop §4.1), for research'"
complete -c mo-dift -l t -d 'Diffusion step the motion is noised to (0..T-1) [default: joints 2, otherwise 3]' -r
complete -c mo-dift -l layer -d 'Layer whose activations are read (0-based) [default: joints 0, otherwise 1]' -r
complete -c mo-dift -l draws -d 'Noise draws averaged' -r
complete -c mo-dift -l model -d 'Model directory written by mo-train [default: the built-in model]' -r -F
complete -c mo-dift -l skeleton -d 'Skeleton (document or BVH) that NPY inputs are decoded on' -r -F
complete -c mo-dift -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c mo-dift -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c mo-dift -l threads -d 'Worker threads (default: all cores; at most 256). Output never depends on this' -r
complete -c mo-dift -l animation -d 'glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first)' -r
complete -c mo-dift -l fps -d 'glTF inputs: sample the animation at this frame rate (default: at its keyframe times)' -r
complete -c mo-dift -l joints -d 'Joint correspondence between REF and TGT (JSON)'
complete -c mo-dift -l frames -d 'Frame correspondence between REF and TGT (JSON)'
complete -c mo-dift -l as-binding -d 'With --joints: write a sparse binding REF -> TGT for mo-retarget --bind'
complete -c mo-dift -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c mo-dift -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c mo-dift -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mo-dift -s V -l version -d 'Print version'
