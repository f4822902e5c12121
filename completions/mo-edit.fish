# Print an optspec for argparse to handle cmd's options that are independent of any subcommand.
function __fish_mo_edit_global_optspecs
    string join \n format= o/output= seed= q/quiet v/verbose threads= animation= fps= h/help V/version
end

function __fish_mo_edit_needs_command
    # Figure out if the current invocation already has a command.
    set -l cmd (commandline -opc)
    set -e cmd[1]
    argparse -s (__fish_mo_edit_global_optspecs) -- $cmd 2>/dev/null
    or return
    if set -q argv[1]
        # Also print the command, so this can be used to figure out what it is.
        echo $argv[1]
        return 1
    end
    return 0
end

function __fish_mo_edit_using_subcommand
    set -l cmd (__fish_mo_edit_needs_command)
    test -z "$cmd"
    and return 1
    contains -- $cmd[1] $argv
end

complete -c mo-edit -n "__fish_mo_edit_needs_command" -l format -d 'Output format when -o has no telling extension or is stdout' -r -f -a "bvh\t''
glb\t'Binary glTF (skin, animation, a stick mesh)'
gltf\t'glTF JSON, data inlined'
npy\t'Motion2Motion features [frames, joints, 9]'"
complete -c mo-edit -n "__fish_mo_edit_needs_command" -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c mo-edit -n "__fish_mo_edit_needs_command" -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c mo-edit -n "__fish_mo_edit_needs_command" -l threads -d 'Worker threads (default: all cores; at most 256). Output never depends on this' -r
complete -c mo-edit -n "__fish_mo_edit_needs_command" -l animation -d 'glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first)' -r
complete -c mo-edit -n "__fish_mo_edit_needs_command" -l fps -d 'glTF inputs: sample the animation at this frame rate (default: at its keyframe times)' -r
complete -c mo-edit -n "__fish_mo_edit_needs_command" -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c mo-edit -n "__fish_mo_edit_needs_command" -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c mo-edit -n "__fish_mo_edit_needs_command" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mo-edit -n "__fish_mo_edit_needs_command" -s V -l version -d 'Print version'
complete -c mo-edit -n "__fish_mo_edit_needs_command" -f -a "convert" -d 'Change the format only'
complete -c mo-edit -n "__fish_mo_edit_needs_command" -f -a "resample" -d 'New frame rate (the global --fps): rotations slerped, positions interpolated'
complete -c mo-edit -n "__fish_mo_edit_needs_command" -f -a "trim" -d 'Keep a range of frames (--frames A:B) or seconds (--seconds S:E), both ends included'
complete -c mo-edit -n "__fish_mo_edit_needs_command" -f -a "concat" -d 'Join clips of one skeleton and frame rate: each starts where and facing how the one before ends (its first frame replaces the previous last), the pose eased across seams'
complete -c mo-edit -n "__fish_mo_edit_needs_command" -f -a "loop" -d 'Make the clip loop: its end eased into its start, its last frame dropped'
complete -c mo-edit -n "__fish_mo_edit_needs_command" -f -a "mirror" -d 'Swap left and right (skel-info\'s sides; partners by name, else by mirrored rest position)'
complete -c mo-edit -n "__fish_mo_edit_needs_command" -f -a "axis" -d 'Re-express rest pose and motion in another axis convention (forward: +z for y-up, -y for z-up)'
complete -c mo-edit -n "__fish_mo_edit_needs_command" -f -a "scale" -d 'Scale OFFSETs and root motion by --factor, or to --to-units (m, cm, mm, in)'
complete -c mo-edit -n "__fish_mo_edit_needs_command" -f -a "in-place" -d 'Remove the root\'s travel over the ground (and its turning, unless --keep-heading)'
complete -c mo-edit -n "__fish_mo_edit_needs_command" -f -a "root" -d 'Replace the root\'s travel and turning with another clip\'s (--path, any skeleton)'
complete -c mo-edit -n "__fish_mo_edit_needs_command" -f -a "rest" -d 'Set the rest pose (OFFSETs) from --frame N, or from frame 0 of --t-pose FILE (same skeleton)'
complete -c mo-edit -n "__fish_mo_edit_needs_command" -f -a "rename" -d 'Rename joints from --map (JSON {\\"old\\": \\"new\\"} or lines \'old new\'), or --normalise them'
complete -c mo-edit -n "__fish_mo_edit_needs_command" -f -a "foot-lock" -d 'Pin feet during contacts (mo-metrics physics\' rule) by two-bone IK; -v reports skating'
complete -c mo-edit -n "__fish_mo_edit_needs_command" -f -a "help" -d 'Print this message or the help of the given subcommand(s)'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand convert" -l format -d 'Output format when -o has no telling extension or is stdout' -r -f -a "bvh\t''
glb\t'Binary glTF (skin, animation, a stick mesh)'
gltf\t'glTF JSON, data inlined'
npy\t'Motion2Motion features [frames, joints, 9]'"
complete -c mo-edit -n "__fish_mo_edit_using_subcommand convert" -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c mo-edit -n "__fish_mo_edit_using_subcommand convert" -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand convert" -l threads -d 'Worker threads (default: all cores; at most 256). Output never depends on this' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand convert" -l animation -d 'glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first)' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand convert" -l fps -d 'glTF inputs: sample the animation at this frame rate (default: at its keyframe times)' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand convert" -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand convert" -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand convert" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand resample" -l format -d 'Output format when -o has no telling extension or is stdout' -r -f -a "bvh\t''
glb\t'Binary glTF (skin, animation, a stick mesh)'
gltf\t'glTF JSON, data inlined'
npy\t'Motion2Motion features [frames, joints, 9]'"
complete -c mo-edit -n "__fish_mo_edit_using_subcommand resample" -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c mo-edit -n "__fish_mo_edit_using_subcommand resample" -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand resample" -l threads -d 'Worker threads (default: all cores; at most 256). Output never depends on this' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand resample" -l animation -d 'glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first)' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand resample" -l fps -d 'glTF inputs: sample the animation at this frame rate (default: at its keyframe times)' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand resample" -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand resample" -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand resample" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand trim" -l frames -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand trim" -l seconds -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand trim" -l format -d 'Output format when -o has no telling extension or is stdout' -r -f -a "bvh\t''
glb\t'Binary glTF (skin, animation, a stick mesh)'
gltf\t'glTF JSON, data inlined'
npy\t'Motion2Motion features [frames, joints, 9]'"
complete -c mo-edit -n "__fish_mo_edit_using_subcommand trim" -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c mo-edit -n "__fish_mo_edit_using_subcommand trim" -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand trim" -l threads -d 'Worker threads (default: all cores; at most 256). Output never depends on this' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand trim" -l animation -d 'glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first)' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand trim" -l fps -d 'glTF inputs: sample the animation at this frame rate (default: at its keyframe times)' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand trim" -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand trim" -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand trim" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand concat" -l blend -d 'Seconds of easing on each side of every seam' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand concat" -l format -d 'Output format when -o has no telling extension or is stdout' -r -f -a "bvh\t''
glb\t'Binary glTF (skin, animation, a stick mesh)'
gltf\t'glTF JSON, data inlined'
npy\t'Motion2Motion features [frames, joints, 9]'"
complete -c mo-edit -n "__fish_mo_edit_using_subcommand concat" -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c mo-edit -n "__fish_mo_edit_using_subcommand concat" -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand concat" -l threads -d 'Worker threads (default: all cores; at most 256). Output never depends on this' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand concat" -l animation -d 'glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first)' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand concat" -l fps -d 'glTF inputs: sample the animation at this frame rate (default: at its keyframe times)' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand concat" -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand concat" -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand concat" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand loop" -l blend -d 'Seconds of easing on each side of the seam' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand loop" -l format -d 'Output format when -o has no telling extension or is stdout' -r -f -a "bvh\t''
glb\t'Binary glTF (skin, animation, a stick mesh)'
gltf\t'glTF JSON, data inlined'
npy\t'Motion2Motion features [frames, joints, 9]'"
complete -c mo-edit -n "__fish_mo_edit_using_subcommand loop" -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c mo-edit -n "__fish_mo_edit_using_subcommand loop" -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand loop" -l threads -d 'Worker threads (default: all cores; at most 256). Output never depends on this' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand loop" -l animation -d 'glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first)' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand loop" -l fps -d 'glTF inputs: sample the animation at this frame rate (default: at its keyframe times)' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand loop" -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand loop" -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand loop" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand mirror" -l format -d 'Output format when -o has no telling extension or is stdout' -r -f -a "bvh\t''
glb\t'Binary glTF (skin, animation, a stick mesh)'
gltf\t'glTF JSON, data inlined'
npy\t'Motion2Motion features [frames, joints, 9]'"
complete -c mo-edit -n "__fish_mo_edit_using_subcommand mirror" -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c mo-edit -n "__fish_mo_edit_using_subcommand mirror" -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand mirror" -l threads -d 'Worker threads (default: all cores; at most 256). Output never depends on this' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand mirror" -l animation -d 'glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first)' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand mirror" -l fps -d 'glTF inputs: sample the animation at this frame rate (default: at its keyframe times)' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand mirror" -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand mirror" -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand mirror" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand axis" -l from -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand axis" -l to -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand axis" -l from-forward -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand axis" -l to-forward -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand axis" -l format -d 'Output format when -o has no telling extension or is stdout' -r -f -a "bvh\t''
glb\t'Binary glTF (skin, animation, a stick mesh)'
gltf\t'glTF JSON, data inlined'
npy\t'Motion2Motion features [frames, joints, 9]'"
complete -c mo-edit -n "__fish_mo_edit_using_subcommand axis" -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c mo-edit -n "__fish_mo_edit_using_subcommand axis" -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand axis" -l threads -d 'Worker threads (default: all cores; at most 256). Output never depends on this' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand axis" -l animation -d 'glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first)' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand axis" -l fps -d 'glTF inputs: sample the animation at this frame rate (default: at its keyframe times)' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand axis" -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand axis" -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand axis" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand scale" -l factor -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand scale" -l to-units -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand scale" -l from-units -d 'The clip\'s units [default: guessed: cm if it is 20 units or more across, else m]' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand scale" -l format -d 'Output format when -o has no telling extension or is stdout' -r -f -a "bvh\t''
glb\t'Binary glTF (skin, animation, a stick mesh)'
gltf\t'glTF JSON, data inlined'
npy\t'Motion2Motion features [frames, joints, 9]'"
complete -c mo-edit -n "__fish_mo_edit_using_subcommand scale" -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c mo-edit -n "__fish_mo_edit_using_subcommand scale" -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand scale" -l threads -d 'Worker threads (default: all cores; at most 256). Output never depends on this' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand scale" -l animation -d 'glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first)' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand scale" -l fps -d 'glTF inputs: sample the animation at this frame rate (default: at its keyframe times)' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand scale" -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand scale" -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand scale" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand in-place" -l format -d 'Output format when -o has no telling extension or is stdout' -r -f -a "bvh\t''
glb\t'Binary glTF (skin, animation, a stick mesh)'
gltf\t'glTF JSON, data inlined'
npy\t'Motion2Motion features [frames, joints, 9]'"
complete -c mo-edit -n "__fish_mo_edit_using_subcommand in-place" -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c mo-edit -n "__fish_mo_edit_using_subcommand in-place" -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand in-place" -l threads -d 'Worker threads (default: all cores; at most 256). Output never depends on this' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand in-place" -l animation -d 'glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first)' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand in-place" -l fps -d 'glTF inputs: sample the animation at this frame rate (default: at its keyframe times)' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand in-place" -l keep-heading
complete -c mo-edit -n "__fish_mo_edit_using_subcommand in-place" -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand in-place" -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand in-place" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand root" -l path -r -F
complete -c mo-edit -n "__fish_mo_edit_using_subcommand root" -l format -d 'Output format when -o has no telling extension or is stdout' -r -f -a "bvh\t''
glb\t'Binary glTF (skin, animation, a stick mesh)'
gltf\t'glTF JSON, data inlined'
npy\t'Motion2Motion features [frames, joints, 9]'"
complete -c mo-edit -n "__fish_mo_edit_using_subcommand root" -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c mo-edit -n "__fish_mo_edit_using_subcommand root" -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand root" -l threads -d 'Worker threads (default: all cores; at most 256). Output never depends on this' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand root" -l animation -d 'glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first)' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand root" -l fps -d 'glTF inputs: sample the animation at this frame rate (default: at its keyframe times)' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand root" -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand root" -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand root" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand rest" -l frame -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand rest" -l t-pose -r -F
complete -c mo-edit -n "__fish_mo_edit_using_subcommand rest" -l format -d 'Output format when -o has no telling extension or is stdout' -r -f -a "bvh\t''
glb\t'Binary glTF (skin, animation, a stick mesh)'
gltf\t'glTF JSON, data inlined'
npy\t'Motion2Motion features [frames, joints, 9]'"
complete -c mo-edit -n "__fish_mo_edit_using_subcommand rest" -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c mo-edit -n "__fish_mo_edit_using_subcommand rest" -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand rest" -l threads -d 'Worker threads (default: all cores; at most 256). Output never depends on this' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand rest" -l animation -d 'glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first)' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand rest" -l fps -d 'glTF inputs: sample the animation at this frame rate (default: at its keyframe times)' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand rest" -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand rest" -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand rest" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand rename" -l map -r -F
complete -c mo-edit -n "__fish_mo_edit_using_subcommand rename" -l format -d 'Output format when -o has no telling extension or is stdout' -r -f -a "bvh\t''
glb\t'Binary glTF (skin, animation, a stick mesh)'
gltf\t'glTF JSON, data inlined'
npy\t'Motion2Motion features [frames, joints, 9]'"
complete -c mo-edit -n "__fish_mo_edit_using_subcommand rename" -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c mo-edit -n "__fish_mo_edit_using_subcommand rename" -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand rename" -l threads -d 'Worker threads (default: all cores; at most 256). Output never depends on this' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand rename" -l animation -d 'glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first)' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand rename" -l fps -d 'glTF inputs: sample the animation at this frame rate (default: at its keyframe times)' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand rename" -l normalise
complete -c mo-edit -n "__fish_mo_edit_using_subcommand rename" -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand rename" -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand rename" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand foot-lock" -l blend -d 'Seconds of easing into and out of each contact' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand foot-lock" -l ground -d 'Ground: \'zero\' (y = 0), \'estimate\' (lowest foot height over the clip) or a height' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand foot-lock" -l contact-height -d 'Contact height threshold, as a fraction of the skeleton\'s size' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand foot-lock" -l contact-speed -d 'Contact speed threshold, as a fraction of the skeleton\'s size per second' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand foot-lock" -l format -d 'Output format when -o has no telling extension or is stdout' -r -f -a "bvh\t''
glb\t'Binary glTF (skin, animation, a stick mesh)'
gltf\t'glTF JSON, data inlined'
npy\t'Motion2Motion features [frames, joints, 9]'"
complete -c mo-edit -n "__fish_mo_edit_using_subcommand foot-lock" -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c mo-edit -n "__fish_mo_edit_using_subcommand foot-lock" -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand foot-lock" -l threads -d 'Worker threads (default: all cores; at most 256). Output never depends on this' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand foot-lock" -l animation -d 'glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first)' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand foot-lock" -l fps -d 'glTF inputs: sample the animation at this frame rate (default: at its keyframe times)' -r
complete -c mo-edit -n "__fish_mo_edit_using_subcommand foot-lock" -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand foot-lock" -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand foot-lock" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand help; and not __fish_seen_subcommand_from convert resample trim concat loop mirror axis scale in-place root rest rename foot-lock help" -f -a "convert" -d 'Change the format only'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand help; and not __fish_seen_subcommand_from convert resample trim concat loop mirror axis scale in-place root rest rename foot-lock help" -f -a "resample" -d 'New frame rate (the global --fps): rotations slerped, positions interpolated'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand help; and not __fish_seen_subcommand_from convert resample trim concat loop mirror axis scale in-place root rest rename foot-lock help" -f -a "trim" -d 'Keep a range of frames (--frames A:B) or seconds (--seconds S:E), both ends included'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand help; and not __fish_seen_subcommand_from convert resample trim concat loop mirror axis scale in-place root rest rename foot-lock help" -f -a "concat" -d 'Join clips of one skeleton and frame rate: each starts where and facing how the one before ends (its first frame replaces the previous last), the pose eased across seams'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand help; and not __fish_seen_subcommand_from convert resample trim concat loop mirror axis scale in-place root rest rename foot-lock help" -f -a "loop" -d 'Make the clip loop: its end eased into its start, its last frame dropped'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand help; and not __fish_seen_subcommand_from convert resample trim concat loop mirror axis scale in-place root rest rename foot-lock help" -f -a "mirror" -d 'Swap left and right (skel-info\'s sides; partners by name, else by mirrored rest position)'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand help; and not __fish_seen_subcommand_from convert resample trim concat loop mirror axis scale in-place root rest rename foot-lock help" -f -a "axis" -d 'Re-express rest pose and motion in another axis convention (forward: +z for y-up, -y for z-up)'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand help; and not __fish_seen_subcommand_from convert resample trim concat loop mirror axis scale in-place root rest rename foot-lock help" -f -a "scale" -d 'Scale OFFSETs and root motion by --factor, or to --to-units (m, cm, mm, in)'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand help; and not __fish_seen_subcommand_from convert resample trim concat loop mirror axis scale in-place root rest rename foot-lock help" -f -a "in-place" -d 'Remove the root\'s travel over the ground (and its turning, unless --keep-heading)'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand help; and not __fish_seen_subcommand_from convert resample trim concat loop mirror axis scale in-place root rest rename foot-lock help" -f -a "root" -d 'Replace the root\'s travel and turning with another clip\'s (--path, any skeleton)'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand help; and not __fish_seen_subcommand_from convert resample trim concat loop mirror axis scale in-place root rest rename foot-lock help" -f -a "rest" -d 'Set the rest pose (OFFSETs) from --frame N, or from frame 0 of --t-pose FILE (same skeleton)'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand help; and not __fish_seen_subcommand_from convert resample trim concat loop mirror axis scale in-place root rest rename foot-lock help" -f -a "rename" -d 'Rename joints from --map (JSON {\\"old\\": \\"new\\"} or lines \'old new\'), or --normalise them'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand help; and not __fish_seen_subcommand_from convert resample trim concat loop mirror axis scale in-place root rest rename foot-lock help" -f -a "foot-lock" -d 'Pin feet during contacts (mo-metrics physics\' rule) by two-bone IK; -v reports skating'
complete -c mo-edit -n "__fish_mo_edit_using_subcommand help; and not __fish_seen_subcommand_from convert resample trim concat loop mirror axis scale in-place root rest rename foot-lock help" -f -a "help" -d 'Print this message or the help of the given subcommand(s)'
