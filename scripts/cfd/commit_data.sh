# Sourced by the CFD runners: commit_data TOP SUBJECT BODY FILE... commits exactly FILE... (paths
# relative to the repository TOP) with that message, retrying while another git command holds the
# index; prints the commit, or says on stderr that it could not and returns 1.
commit_data() {
  local top="$1" subject="$2" body="$3"
  shift 3
  for attempt in 1 2 3 4 5 6 7 8 9 10; do
    if [ ! -f "$top/.git/index.lock" ] && (cd "$top" && git add -- "$@" &&
        git commit -q -m "$subject" -m "$body" -- "$@"); then
      echo "committed $(cd "$top" && git rev-parse --short HEAD)"
      return 0
    fi
    sleep 3
  done
  echo "could not commit $* (index locked?)" >&2
  return 1
}
