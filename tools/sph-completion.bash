# Bash completion for sph. Commands, each command's options (read from
# `sph help COMMAND`, so they follow the binary), shipped scene names
# (`sph list`) and, after --set or --vary, the scene's keys with every
# default filled in (`sph check SCENE --keys`). Install: source this file, or copy it to
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
  --set | --vary)
    local scene=twisting_column i
    for ((i = 2; i < COMP_CWORD; ++i)); do
      case "${COMP_WORDS[i - 1]}" in
      --set | --vary | --out | --resume | --threads | --repeat | --resolution | --json | --device) continue ;;
      esac
      if [[ "${COMP_WORDS[i]}" != -* ]]; then
        scene=${COMP_WORDS[i]}
        break
      fi
    done
    local keys
    keys=$("$sph" check "$scene" --keys 2>/dev/null | sed 's/$/=/')
    compopt -o nospace 2>/dev/null
    COMPREPLY=($(compgen -W "$keys" -- "$cur"))
    return
    ;;
  --device)
    COMPREPLY=($(compgen -W "cpu cuda" -- "$cur"))
    return
    ;;
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
