complete -c skel-aug -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c skel-aug -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c skel-aug -l threads -d 'Worker threads (default: all cores). Output never depends on this' -r
complete -c skel-aug -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c skel-aug -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c skel-aug -s h -l help -d 'Print help (see more with \'--help\')'
complete -c skel-aug -s V -l version -d 'Print version'
