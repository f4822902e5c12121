_mo__encode() {
    local i cur prev opts cmd
    COMPREPLY=()
    if [[ "${BASH_VERSINFO[0]}" -ge 4 ]]; then
        cur="$2"
    else
        cur="${COMP_WORDS[COMP_CWORD]}"
    fi
    prev="$3"
    cmd=""
    opts=""

    for i in "${COMP_WORDS[@]:0:COMP_CWORD}"
    do
        case "${cmd},${i}" in
            ",$1")
                cmd="mo__encode"
                ;;
            *)
                ;;
        esac
    done

    case "${cmd}" in
        mo__encode)
            opts="-o -q -v -h -V --repr --decode --skeleton --rest-pose --face-joints --body-axis --feet --require-contacts --normalise --stats --emit-skeleton --placement --from --normalised --latent --decode-latent --model --output --seed --quiet --verbose --threads --animation --fps --help --version"
            if [[ ${cur} == -* || ${COMP_CWORD} -eq 1 ]] ; then
                COMPREPLY=( $(compgen -W "${opts}" -- "${cur}") )
                return 0
            fi
            case "${prev}" in
                --repr)
                    COMPREPLY=($(compgen -W "anytop m2m" -- "${cur}"))
                    return 0
                    ;;
                --skeleton)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --rest-pose)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --face-joints)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --body-axis)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --feet)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --stats)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --emit-skeleton)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --placement)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --from)
                    COMPREPLY=($(compgen -W "rotations positions" -- "${cur}"))
                    return 0
                    ;;
                --model)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --output)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                -o)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --seed)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --threads)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --animation)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --fps)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                *)
                    COMPREPLY=()
                    ;;
            esac
            COMPREPLY=( $(compgen -W "${opts}" -- "${cur}") )
            return 0
            ;;
    esac
}

if [[ "${BASH_VERSINFO[0]}" -eq 4 && "${BASH_VERSINFO[1]}" -ge 4 || "${BASH_VERSINFO[0]}" -gt 4 ]]; then
    complete -F _mo__encode -o nosort -o bashdefault -o default mo-encode
else
    complete -F _mo__encode -o bashdefault -o default mo-encode
fi
