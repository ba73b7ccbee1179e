# Bash completion for sph. Commands, each command's options (read from
# `sph help COMMAND`, so they follow the binary) and shipped scene names
# (`sph list`). Install: source this file, or copy it to
# /usr/share/bash-completion/completions/sph.
_sph() {
  local cur prev cmd
  cur=${COMP_WORDS[COMP_CWORD]}
  prev=${COMP_WORDS[COMP_CWORD - 1]}
  cmd=${COMP_WORDS[1]}
  local sph=${COMP_WORDS[0]}
  if [ "$COMP_CWORD" -eq 1 ]; then
    COMPREPLY=($(compgen -W "run check study list imgdiff bench render help --version --help" -- "$cur"))
    return
  fi
  case "$prev" in
  --out | --resume | --json | --diff)
    COMPREPLY=($(compgen -f -- "$cur"))
    return
    ;;
  esac
  if [ "$cmd" = help ]; then
    COMPREPLY=($(compgen -W "run check study list imgdiff bench render" -- "$cur"))
    return
  fi
  if [[ "$cur" == -* ]]; then
    local opts
    opts=$("$sph" help "$cmd" 2>/dev/null | grep -o -- '--[a-z][a-z-]*' | sort -u)
    COMPREPLY=($(compgen -W "$opts --help" -- "$cur"))
    return
  fi
  case "$cmd" in
  run | check | study)
    local scenes
    scenes=$("$sph" list 2>/dev/null | awk '{print $1}')
    COMPREPLY=($(compgen -W "$scenes" -- "$cur") $(compgen -f -X '!*.yaml' -- "$cur"))
    ;;
  render | imgdiff)
    COMPREPLY=($(compgen -f -- "$cur"))
    ;;
  esac
}
complete -F _sph sph
