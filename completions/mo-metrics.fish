# Print an optspec for argparse to handle cmd's options that are independent of any subcommand.
function __fish_mo_metrics_global_optspecs
    string join \n format= skeleton= from= o/output= seed= q/quiet v/verbose threads= animation= fps= h/help V/version
end

function __fish_mo_metrics_needs_command
    # Figure out if the current invocation already has a command.
    set -l cmd (commandline -opc)
    set -e cmd[1]
    argparse -s (__fish_mo_metrics_global_optspecs) -- $cmd 2>/dev/null
    or return
    if set -q argv[1]
        # Also print the command, so this can be used to figure out what it is.
        echo $argv[1]
        return 1
    end
    return 0
end

function __fish_mo_metrics_using_subcommand
    set -l cmd (__fish_mo_metrics_needs_command)
    test -z "$cmd"
    and return 1
    contains -- $cmd[1] $argv
end

complete -c mo-metrics -n "__fish_mo_metrics_needs_command" -l format -d 'Output format' -r -f -a "json\t''
table\t''"
complete -c mo-metrics -n "__fish_mo_metrics_needs_command" -l skeleton -d 'Skeleton of NPY inputs: a skeleton document (skel-info) or a BVH file' -r -F
complete -c mo-metrics -n "__fish_mo_metrics_needs_command" -l from -d 'AnyTop features: pose from their rotations or (generated clips) their positions by IK' -r -f -a "rotations\t'The features\' 6D rotations: exact for encoded features'
positions\t'The features\' joint positions, by inverse kinematics: for generated features'"
complete -c mo-metrics -n "__fish_mo_metrics_needs_command" -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c mo-metrics -n "__fish_mo_metrics_needs_command" -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c mo-metrics -n "__fish_mo_metrics_needs_command" -l threads -d 'Worker threads (default: all cores; at most 256). Output never depends on this' -r
complete -c mo-metrics -n "__fish_mo_metrics_needs_command" -l animation -d 'glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first)' -r
complete -c mo-metrics -n "__fish_mo_metrics_needs_command" -l fps -d 'glTF inputs: sample the animation at this frame rate (default: at its keyframe times)' -r
complete -c mo-metrics -n "__fish_mo_metrics_needs_command" -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c mo-metrics -n "__fish_mo_metrics_needs_command" -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c mo-metrics -n "__fish_mo_metrics_needs_command" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mo-metrics -n "__fish_mo_metrics_needs_command" -s V -l version -d 'Print version'
complete -c mo-metrics -n "__fish_mo_metrics_needs_command" -f -a "ood" -d 'How far skeletons lie from a learned model\'s training skeletons (the out-of-distribution score behind the warning of mo-sample, mo-dift, mo-segment, mo-encode --latent and mo-retarget --method latent)'
complete -c mo-metrics -n "__fish_mo_metrics_needs_command" -f -a "generation" -d 'AnyTop\'s generation metrics: generated samples against ground-truth clips of one skeleton'
complete -c mo-metrics -n "__fish_mo_metrics_needs_command" -f -a "transfer" -d 'Motion2Motion\'s transfer metrics: results against their source and the target\'s examples'
complete -c mo-metrics -n "__fish_mo_metrics_needs_command" -f -a "reconstruction" -d 'SATA\'s reconstruction metrics: a result against a reference motion on the same skeleton'
complete -c mo-metrics -n "__fish_mo_metrics_needs_command" -f -a "aggregate" -d 'The paper\'s table row: mean and std over skeletons of per-skeleton generation results'
complete -c mo-metrics -n "__fish_mo_metrics_needs_command" -f -a "physics" -d 'Physical plausibility of any motion: foot skating, ground penetration, floating, jitter'
complete -c mo-metrics -n "__fish_mo_metrics_needs_command" -f -a "help" -d 'Print this message or the help of the given subcommand(s)'
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand ood" -l model -d 'Model directory [default: the built-in diffusion model, or with --latent the built-in latent model]' -r -F
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand ood" -l format -d 'Output format' -r -f -a "json\t''
table\t''"
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand ood" -l skeleton -d 'Skeleton of NPY inputs: a skeleton document (skel-info) or a BVH file' -r -F
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand ood" -l from -d 'AnyTop features: pose from their rotations or (generated clips) their positions by IK' -r -f -a "rotations\t'The features\' 6D rotations: exact for encoded features'
positions\t'The features\' joint positions, by inverse kinematics: for generated features'"
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand ood" -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand ood" -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand ood" -l threads -d 'Worker threads (default: all cores; at most 256). Output never depends on this' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand ood" -l animation -d 'glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first)' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand ood" -l fps -d 'glTF inputs: sample the animation at this frame rate (default: at its keyframe times)' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand ood" -l latent -d 'Score against a latent model (SATA: mo-encode --latent, mo-retarget --method latent)'
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand ood" -l unseen -d 'Score against the diffusion model\'s unseen-skeleton denoiser (DIR/unseen; the built-in has one) and its limit: how mo-sample judges a skeleton the main denoiser was not trained on, which it samples with that denoiser'
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand ood" -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand ood" -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand ood" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand generation" -l gt -d 'Ground-truth clips (files or directories)' -r -F
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand generation" -l gen -d 'Generated samples (files or directories; an NPY batch gives one sample per row)' -r -F
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand generation" -l window -d 'Window length of coverage and local diversity, in frames' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand generation" -l threshold -d 'Coverage threshold on the mean joint distance (AnyTop\'s units)' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand generation" -l min-segment -d 'Shortest segment of the global-diversity segmentation, in frames' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand generation" -l format -d 'Output format' -r -f -a "json\t''
table\t''"
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand generation" -l skeleton -d 'Skeleton of NPY inputs: a skeleton document (skel-info) or a BVH file' -r -F
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand generation" -l from -d 'AnyTop features: pose from their rotations or (generated clips) their positions by IK' -r -f -a "rotations\t'The features\' 6D rotations: exact for encoded features'
positions\t'The features\' joint positions, by inverse kinematics: for generated features'"
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand generation" -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand generation" -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand generation" -l threads -d 'Worker threads (default: all cores; at most 256). Output never depends on this' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand generation" -l animation -d 'glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first)' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand generation" -l fps -d 'glTF inputs: sample the animation at this frame rate (default: at its keyframe times)' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand generation" -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand generation" -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand generation" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand transfer" -l source -d 'The source motion' -r -F
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand transfer" -l result -d 'Result motions on the target skeleton (files or directories)' -r -F
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand transfer" -l binding -d 'Binding source joint -> target joint (ours or the reference\'s mapping JSON) [default: joints with the same (normalised) names]' -r -F
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand transfer" -l examples -d 'The target\'s example clips, the real set of the FIDs (files or directories)' -r -F
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand transfer" -l seconds -d 'Seconds the results took to make (for throughput)' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand transfer" -l fid-window -d 'Cut examples and results into windows of this many frames for the FIDs (a set of one or two clips has no covariance; the windows make sets). 0 = whole clips' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand transfer" -l format -d 'Output format' -r -f -a "json\t''
table\t''"
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand transfer" -l skeleton -d 'Skeleton of NPY inputs: a skeleton document (skel-info) or a BVH file' -r -F
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand transfer" -l from -d 'AnyTop features: pose from their rotations or (generated clips) their positions by IK' -r -f -a "rotations\t'The features\' 6D rotations: exact for encoded features'
positions\t'The features\' joint positions, by inverse kinematics: for generated features'"
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand transfer" -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand transfer" -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand transfer" -l threads -d 'Worker threads (default: all cores; at most 256). Output never depends on this' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand transfer" -l animation -d 'glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first)' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand transfer" -l fps -d 'glTF inputs: sample the animation at this frame rate (default: at its keyframe times)' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand transfer" -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand transfer" -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand transfer" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand reconstruction" -l reference -d 'The ground truth' -r -F
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand reconstruction" -l result -d 'The motion to score (same skeleton, same frame count)' -r -F
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand reconstruction" -l height -d 'Height used by the retargeting error [default: the reference skeleton\'s rest height]' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand reconstruction" -l format -d 'Output format' -r -f -a "json\t''
table\t''"
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand reconstruction" -l skeleton -d 'Skeleton of NPY inputs: a skeleton document (skel-info) or a BVH file' -r -F
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand reconstruction" -l from -d 'AnyTop features: pose from their rotations or (generated clips) their positions by IK' -r -f -a "rotations\t'The features\' 6D rotations: exact for encoded features'
positions\t'The features\' joint positions, by inverse kinematics: for generated features'"
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand reconstruction" -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand reconstruction" -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand reconstruction" -l threads -d 'Worker threads (default: all cores; at most 256). Output never depends on this' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand reconstruction" -l animation -d 'glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first)' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand reconstruction" -l fps -d 'glTF inputs: sample the animation at this frame rate (default: at its keyframe times)' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand reconstruction" -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand reconstruction" -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand reconstruction" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand aggregate" -l format -d 'Output format' -r -f -a "json\t''
table\t''"
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand aggregate" -l skeleton -d 'Skeleton of NPY inputs: a skeleton document (skel-info) or a BVH file' -r -F
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand aggregate" -l from -d 'AnyTop features: pose from their rotations or (generated clips) their positions by IK' -r -f -a "rotations\t'The features\' 6D rotations: exact for encoded features'
positions\t'The features\' joint positions, by inverse kinematics: for generated features'"
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand aggregate" -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand aggregate" -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand aggregate" -l threads -d 'Worker threads (default: all cores; at most 256). Output never depends on this' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand aggregate" -l animation -d 'glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first)' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand aggregate" -l fps -d 'glTF inputs: sample the animation at this frame rate (default: at its keyframe times)' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand aggregate" -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand aggregate" -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand aggregate" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand physics" -l ground -d 'Ground: \'zero\' (y = 0), \'estimate\' (lowest foot height over the clip) or a height' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand physics" -l contact-height -d 'Contact height threshold, as a fraction of the skeleton\'s size' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand physics" -l contact-speed -d 'Contact speed threshold, as a fraction of the skeleton\'s size per second' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand physics" -l format -d 'Output format' -r -f -a "json\t''
table\t''"
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand physics" -l skeleton -d 'Skeleton of NPY inputs: a skeleton document (skel-info) or a BVH file' -r -F
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand physics" -l from -d 'AnyTop features: pose from their rotations or (generated clips) their positions by IK' -r -f -a "rotations\t'The features\' 6D rotations: exact for encoded features'
positions\t'The features\' joint positions, by inverse kinematics: for generated features'"
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand physics" -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand physics" -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand physics" -l threads -d 'Worker threads (default: all cores; at most 256). Output never depends on this' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand physics" -l animation -d 'glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first)' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand physics" -l fps -d 'glTF inputs: sample the animation at this frame rate (default: at its keyframe times)' -r
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand physics" -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand physics" -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand physics" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand help; and not __fish_seen_subcommand_from ood generation transfer reconstruction aggregate physics help" -f -a "ood" -d 'How far skeletons lie from a learned model\'s training skeletons (the out-of-distribution score behind the warning of mo-sample, mo-dift, mo-segment, mo-encode --latent and mo-retarget --method latent)'
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand help; and not __fish_seen_subcommand_from ood generation transfer reconstruction aggregate physics help" -f -a "generation" -d 'AnyTop\'s generation metrics: generated samples against ground-truth clips of one skeleton'
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand help; and not __fish_seen_subcommand_from ood generation transfer reconstruction aggregate physics help" -f -a "transfer" -d 'Motion2Motion\'s transfer metrics: results against their source and the target\'s examples'
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand help; and not __fish_seen_subcommand_from ood generation transfer reconstruction aggregate physics help" -f -a "reconstruction" -d 'SATA\'s reconstruction metrics: a result against a reference motion on the same skeleton'
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand help; and not __fish_seen_subcommand_from ood generation transfer reconstruction aggregate physics help" -f -a "aggregate" -d 'The paper\'s table row: mean and std over skeletons of per-skeleton generation results'
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand help; and not __fish_seen_subcommand_from ood generation transfer reconstruction aggregate physics help" -f -a "physics" -d 'Physical plausibility of any motion: foot skating, ground penetration, floating, jitter'
complete -c mo-metrics -n "__fish_mo_metrics_using_subcommand help; and not __fish_seen_subcommand_from ood generation transfer reconstruction aggregate physics help" -f -a "help" -d 'Print this message or the help of the given subcommand(s)'
