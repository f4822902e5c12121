_mo__train() {
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
                cmd="mo__train"
                ;;
            *)
                ;;
        esac
    done

    case "${cmd}" in
        mo__train)
            opts="-o -q -v -h -V --out --preset --steps --minutes --init --batch --crop --arch --lambda-kl --lambda-cycle --lr --lambda-geo --lambda-vel --lambda-foot --augment --augment-variants --fallback-stats --loss-units --rest-token --ema --noise-shift --loss-weighting --position-jitter --shift-taper --still-weight --checkpoint-minutes --resume --output --seed --quiet --verbose --threads --animation --fps --help --version"
            if [[ ${cur} == -* || ${COMP_CWORD} -eq 1 ]] ; then
                COMPREPLY=( $(compgen -W "${opts}" -- "${cur}") )
                return 0
            fi
            case "${prev}" in
                --out)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --preset)
                    COMPREPLY=($(compgen -W "tiny compact small paper" -- "${cur}"))
                    return 0
                    ;;
                --steps)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --minutes)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --init)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --batch)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --crop)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --arch)
                    COMPREPLY=($(compgen -W "anytop sata" -- "${cur}"))
                    return 0
                    ;;
                --lambda-kl)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --lambda-cycle)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --lr)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --lambda-geo)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --lambda-vel)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --lambda-foot)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --augment)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --augment-variants)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --fallback-stats)
                    COMPREPLY=($(compgen -W "none variants all" -- "${cur}"))
                    return 0
                    ;;
                --loss-units)
                    COMPREPLY=($(compgen -W "normalised own" -- "${cur}"))
                    return 0
                    ;;
                --rest-token)
                    COMPREPLY=($(compgen -W "skeleton global" -- "${cur}"))
                    return 0
                    ;;
                --ema)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --noise-shift)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --loss-weighting)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --position-jitter)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --shift-taper)
                    COMPREPLY=($(compgen -W "true false" -- "${cur}"))
                    return 0
                    ;;
                --still-weight)
                    COMPREPLY=($(compgen -f "${cur}"))
                    return 0
                    ;;
                --checkpoint-minutes)
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
    complete -F _mo__train -o nosort -o bashdefault -o default mo-train
else
    complete -F _mo__train -o bashdefault -o default mo-train
fi
