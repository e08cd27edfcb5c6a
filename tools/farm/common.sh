# Sourced by the farm scripts (tools/farm/*.sh, tools/slurm/submit.sh): errors
# that name the script, and the checks of their whole-number options.

# Prints "SCRIPT: error: MESSAGE" and exits with status 2 (bad input).
fail() {
  echo "${0##*/}: error: $*" >&2
  exit 2
}

whole_number() { [[ $1 =~ ^[0-9]+$ ]]; }

# count OPTION VALUE: VALUE as a decimal number of at least 1 (leading zeros
# are not octal), or a failure naming the option.
count() {
  whole_number "$2" && ((10#$2 >= 1)) || fail "$1 $2: expected a whole number of at least 1"
  echo $((10#$2))
}
