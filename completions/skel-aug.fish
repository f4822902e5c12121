complete -c skel-aug -l remove-rate -d 'Remove this fraction of the joints, in (0, 1), rounded, at least one [default: a count between 10% and 30% of the joints, drawn from the seed]' -r
complete -c skel-aug -l add -d 'Insert N joints, each at the midpoint of a random bone (after any removal)' -r
complete -c skel-aug -s n -l variants -d 'Write K variants with different random choices (-o must then contain \'{i}\')' -r
complete -c skel-aug -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c skel-aug -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c skel-aug -l threads -d 'Worker threads (default: all cores; at most 256). Output never depends on this' -r
complete -c skel-aug -l animation -d 'glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first)' -r
complete -c skel-aug -l fps -d 'glTF inputs: sample the animation at this frame rate (default: at its keyframe times)' -r
complete -c skel-aug -l no-remove -d 'Remove nothing (to only --add)'
complete -c skel-aug -l allow-feet -d 'Let removal take feet too (for bodies that lie on the ground, like snakes, whose joints are all feet; AnyTop does the same for its snakes)'
complete -c skel-aug -l pretty -d 'Indent JSON output for humans (skeleton documents only)'
complete -c skel-aug -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c skel-aug -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c skel-aug -s h -l help -d 'Print help (see more with \'--help\')'
complete -c skel-aug -s V -l version -d 'Print version'
