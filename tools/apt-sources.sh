# Sourced by the tools that need a Debian archive (check-debian13.sh,
# build-lavapipe.sh): the archives come from the host's own apt sources, so
# that no tool names a mirror of its own.

# Prints "URI SUITE" for every enabled source of the host, one per line, from
# both the one-line format (*.list) and the deb822 format (*.sources).
host_apt_sources() {
  local file
  for file in /etc/apt/sources.list /etc/apt/sources.list.d/*.list; do
    [[ -f $file ]] || continue
    # deb [options] URI SUITE COMPONENTS...
    sed -e 's/#.*//' -e 's/\[[^]]*\]//' "$file" | awk '$1 == "deb" { print $2, $3 }'
  done
  for file in /etc/apt/sources.list.d/*.sources; do
    [[ -f $file ]] || continue
    awk '
      function flush() {
        if (enabled && types ~ /(^| )deb( |$)/)
          for (u = 1; u <= nu; u++) for (s = 1; s <= ns; s++) print uris[u], suites[s]
        types = ""; nu = ns = 0; enabled = 1
      }
      BEGIN { enabled = 1 }
      /^[[:space:]]*#/ { next }
      /^[[:space:]]*$/ { flush(); next }
      {
        key = tolower($1); sub(/:$/, "", key)
        if (key == "types") { types = ""; for (i = 2; i <= NF; i++) types = types " " $i; types = types " " }
        else if (key == "uris") for (i = 2; i <= NF; i++) uris[++nu] = $i
        else if (key == "suites") for (i = 2; i <= NF; i++) suites[++ns] = $i
        else if (key == "enabled" && tolower($2) == "no") enabled = 0
      }
      END { flush() }' "$file"
  done
}

# The first archive URI of the host's sources that serves a release, not its
# security updates (whose pool holds only those): where Debian's source
# packages of any release can be fetched from (pool/main/...). Empty if none.
host_debian_archive() {
  host_apt_sources | awk '$2 !~ /-security$/ { print $1; exit }'
}
