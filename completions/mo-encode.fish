complete -c mo-encode -l repr -d 'Feature representation' -r -f -a "m2m\t'Motion2Motion: local 6D rotation of every joint + root position (x/z as velocities); 9 dims'"
complete -c mo-encode -l skeleton -d 'Skeleton to decode onto: a skel-info document (JSON) or a BVH file (\'-\' = stdin)' -r -F
complete -c mo-encode -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c mo-encode -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c mo-encode -l threads -d 'Worker threads (default: all cores). Output never depends on this' -r
complete -c mo-encode -l decode -d 'Decode an NPY of features back to BVH on --skeleton'
complete -c mo-encode -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c mo-encode -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c mo-encode -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mo-encode -s V -l version -d 'Print version'
