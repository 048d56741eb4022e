# SPDX-License-Identifier: MIT
# bash completion for foldest: commands, each command's options, the values
# of --model and --noise, the effects of synth and the terms of --base, and
# file names elsewhere.  Installed as share/bash-completion/completions/foldest.

_foldest()
{
    local cur prev cmd common opts
    COMPREPLY=()
    cur=${COMP_WORDS[COMP_CWORD]}
    prev=${COMP_WORDS[COMP_CWORD-1]}
    cmd=${COMP_WORDS[1]}
    common="--help --version --decimal-comma --skip-bad-rows"
    if [ "$COMP_CWORD" -eq 1 ]; then
        COMPREPLY=($(compgen -W "stats calibrate discover synth help --help --version" -- "$cur"))
        return 0
    fi
    case "$cmd" in
        stats) opts="--columns --skip --json --threads" ;;
        calibrate) opts="--model --columns --apply --skip --json --trace --field --export
                         --mgauss --static --window --still-sd --gyro --max-rate --robust
                         --robust-k --report --threads" ;;
        discover) opts="--real --sim --channel --time --role --base --holdout --noise --lags --blocks
                        --alpha --order --report --json --sphere --columns --term --terms
                        --only --exclude --threads" ;;
        synth) opts="--effect --real --sim --seed --rows --order --rho" ;;
        *) return 0 ;;
    esac
    case "$prev" in
        --model) COMPREPLY=($(compgen -W "sphere axial ellipsoid" -- "$cur")); return 0 ;;
        --export) COMPREPLY=($(compgen -W "ardupilot c json" -- "$cur")); return 0 ;;
        --noise) COMPREPLY=($(compgen -W "ar batch" -- "$cur")); return 0 ;;
        --order) COMPREPLY=($(compgen -W "0 1 2" -- "$cur")); return 0 ;;
        --effect) COMPREPLY=($(compgen -W "bias drift gain delay viscous_friction quadratic_drag
                        coulomb_friction linear_stiffness cubic_stiffness thermal_sensitivity
                        newton_cooling radiative_cooling input_gain none none_thermal" -- "$cur"))
                  return 0 ;;
        --role) COMPREPLY=($(compgen -W "position velocity temperature ambient input" -- "${cur#*=}"))
                [ "${cur#*=}" != "$cur" ] && COMPREPLY=("${COMPREPLY[@]/#/${cur%%=*}=}")
                return 0 ;;
        --columns|--channel|--time|--base|--holdout|--lags|--blocks|--alpha|--seed|--rows|--skip|--term|--only|--exclude) return 0 ;;
        --terms) COMPREPLY=($(compgen -f -- "$cur")); return 0 ;;
        --report) COMPREPLY=($(compgen -d -- "$cur")); return 0 ;;
    esac
    if [[ "$cur" == -* ]]; then
        COMPREPLY=($(compgen -W "$opts $common" -- "$cur"))
    else
        COMPREPLY=($(compgen -f -- "$cur"))
    fi
    return 0
}
complete -o filenames -F _foldest foldest
