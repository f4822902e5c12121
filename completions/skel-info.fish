complete -c skel-info -l format -d 'Output format' -r -f -a "json\t''
text\t''"
complete -c skel-info -l dmax -d 'Cap for graph distances D (AnyTop uses 5)' -r
complete -c skel-info -l rest-pose -d 'Take AnyTop\'s natural rest pose from frame 0 of this BVH (same skeleton) instead of frame 0 of each input' -r -F
complete -c skel-info -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c skel-info -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c skel-info -l threads -d 'Worker threads (default: all cores; at most 256). Output never depends on this' -r
complete -c skel-info -l animation -d 'glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first)' -r
complete -c skel-info -l fps -d 'glTF inputs: sample the animation at this frame rate (default: at its keyframe times)' -r
complete -c skel-info -l pretty -d 'Indent the JSON for humans'
complete -c skel-info -l no-anytop -d 'Leave out the AnyTop record (rig, rest-pose features P_S, normalisation statistics)'
complete -c skel-info -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c skel-info -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c skel-info -s h -l help -d 'Print help (see more with \'--help\')'
complete -c skel-info -s V -l version -d 'Print version'
