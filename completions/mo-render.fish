complete -c mo-render -l sheet -d 'Write a PNG contact sheet here' -r -F
complete -c mo-render -l gif -d 'Write an animated GIF here' -r -F
complete -c mo-render -l html -d 'Write a self-contained HTML viewer here' -r -F
complete -c mo-render -l format -d 'What -o (or stdout) gets when its extension does not say [possible values: sheet, gif, html]' -r -f -a "sheet\t''
gif\t''
html\t''"
complete -c mo-render -l skeleton -d 'Skeleton of NPY inputs: a skeleton document (skel-info) or a BVH file' -r -F
complete -c mo-render -l from -d 'AnyTop features: pose from their rotations (exact for encoded clips) or their positions (inverse kinematics, for generated clips)' -r -f -a "rotations\t'The features\' 6D rotations: exact for encoded features'
positions\t'The features\' joint positions, by inverse kinematics: for generated features'"
complete -c mo-render -l view -d 'Camera: auto, side, front, top, or YAW,PITCH in degrees (yaw about +y, 0 = side; pitch > 0 looks down)' -r
complete -c mo-render -l frames -d 'Draw only frames START:END (END exclusive; either may be omitted: \'100:\', \':50\')' -r
complete -c mo-render -l every -d 'Sheet: draw every K-th frame [default: chosen so each motion fills at most --rows rows]' -r
complete -c mo-render -l columns -d 'Sheet: cells per row' -r
complete -c mo-render -l rows -d 'Sheet: at most this many rows per motion when --every is not given' -r
complete -c mo-render -l size -d 'Size of a sheet cell or a GIF panel in pixels, WIDTHxHEIGHT [default: 160x160 for sheets, 256x256 for GIFs]' -r
complete -c mo-render -l joint-labels -d 'JSON file of per-joint labels (colours joints and bones)' -r -F
complete -c mo-render -l frame-labels -d 'JSON file of per-frame labels (tints frames), e.g. mo-segment\'s output' -r -F
complete -c mo-render -l speed -d 'HTML: initial playback speed' -r
complete -c mo-render -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c mo-render -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c mo-render -l threads -d 'Worker threads (default: all cores; at most 256). Output never depends on this' -r
complete -c mo-render -l animation -d 'glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first)' -r
complete -c mo-render -l fps -d 'glTF inputs: sample the animation at this frame rate (default: at its keyframe times)' -r
complete -c mo-render -l fixed-camera -d 'One camera for the whole clip (shows travel) instead of following the body'
complete -c mo-render -l overlay -d 'HTML: draw all motions in one scene instead of side by side'
complete -c mo-render -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c mo-render -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c mo-render -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mo-render -s V -l version -d 'Print version'
