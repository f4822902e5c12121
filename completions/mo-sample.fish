complete -c mo-sample -l skeleton -d 'The same as SKELETON, as a named option' -r -F
complete -c mo-sample -l model -d 'Model directory written by mo-train, with an optional unseen/ model directory beside its files for skeletons it was not trained on [default: the built-in model, a compact denoiser pair trained on the synthetic zoo; see models/zoo-compact/MODEL_CARD.md]' -r -F
complete -c mo-sample -s n -l samples -d 'Number of samples' -r
complete -c mo-sample -l frames -d 'Frames per sample [default: 120; with --reference: the reference\'s length; with --examples: the longest clip\'s]' -r
complete -c mo-sample -l seconds -d 'Length in seconds (at the skeleton\'s frame rate)' -r
complete -c mo-sample -l steps -d 'Diffusion steps to visit (1..=100)' -r
complete -c mo-sample -l sampler -d 'Sampler' -r -f -a "ddpm\t'Ancestral DDPM (the reference\'s, on all steps; respaced on fewer)'
ddim\t'Deterministic DDIM (η = 0)'"
complete -c mo-sample -l bvh -d 'Write BVH files instead of NPY (\'{i}\' becomes the sample index); named .glb or .gltf: glTF' -r -F
complete -c mo-sample -l reference -d 'A clip of the same skeleton (BVH) to keep parts of (needs --keep-frames or --keep-joints)' -r -F
complete -c mo-sample -l keep-frames -d 'In-betweening: output frames taken from the reference, e.g. \'0-19,100-119\' (inclusive)' -r
complete -c mo-sample -l keep-joints -d 'Body-part editing: joints taken from the reference: names or globs (\'*Leg*\'), \'Name/\' for a joint and all its descendants, comma-separated' -r
complete -c mo-sample -l examples -d 'Example-based generation, no model (GenMM): clips of the skeleton, BVH files or directories of them' -r -F
complete -c mo-sample -l smooth -d 'Low-pass the generated frames over time: the cutoff in Hz where motion keeps half its amplitude (kept frames and joints stay exact; 0 = the model\'s raw output)' -r
complete -c mo-sample -l blend -d 'Editing with --smooth: generated frames next to kept ones give way to them over this many seconds, continuing the kept motion instead of jumping to the generated one' -r
complete -c mo-sample -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c mo-sample -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c mo-sample -l threads -d 'Worker threads (default: all cores; at most 256). Output never depends on this' -r
complete -c mo-sample -l animation -d 'glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first)' -r
complete -c mo-sample -l fps -d 'glTF inputs: sample the animation at this frame rate (default: at its keyframe times)' -r
complete -c mo-sample -l report -d 'Print seam continuity as one JSON line on stderr (with --reference), or with --examples the synthesis levels and match costs'
complete -c mo-sample -l no-plant-feet -d 'Keep the model\'s root travel even where it makes planted feet slide (by default the root\'s horizontal motion follows the feet the model puts on the ground)'
complete -c mo-sample -l lock-feet -d 'Hold planted feet in place: in the last sampling steps (the last three of DDIM\'s 10) each foot the model puts down near the ground is held where it landed, its leg bent to reach, and the remaining steps fit the body to it. Measured on the built-in model (models/zoo-compact/MODEL_CARD.md): the zoo quadruped\'s feet slide 0.39 -> 0.11 body sizes/s (its clips 0-0.12) with poses as near its clips, but it moves a fifth less and the spider 28% less; so it is not the default'
complete -c mo-sample -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c mo-sample -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c mo-sample -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mo-sample -s V -l version -d 'Print version'
