#!/usr/bin/env bash
# The clamp rerun in progress (issue 28, item 3): the thesis-square
# experiments whose files still pin `walls = "segments"`, run with that pin
# removed (the *.toml here are those files without it). Finished trials are
# kept here, so any sitting (or a fresh clone) resumes the run:
#
#   docs/reproduction/pending/run.sh             run what is missing, in order
#   docs/reproduction/pending/run.sh --collect   copy finished trials back here
#
# When every experiment has its 10 trials per arm: drop the pin from
# experiments/*.toml, move each <name>/ here to docs/reproduction/<name>/,
# render (`scripts/reproduce --publish ...`) and rewrite the page's claims.
set -uo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../../.." && pwd)"
work="$root/out/reproduction-pending"
names=(letters-generated)
mkdir -p "$work"

collect() {
    for name in "${names[@]}"; do
        for d in trials pretrained; do
            [[ -d "$work/$name/$d" ]] && mkdir -p "$here/$name" && cp -r "$work/$name/$d" "$here/$name/"
        done
    done
    return 0
}

if [[ "${1:-}" == "--collect" ]]; then
    collect
    exit 0
fi

(cd "$root" && cargo build --release -p host)
cp "$root/target/release/host" "$work/host"
for name in "${names[@]}"; do
    mkdir -p "$work/$name"
    for d in trials pretrained; do
        [[ -d "$here/$name/$d" ]] && cp -rn "$here/$name/$d" "$work/$name/"
    done
done
for name in "${names[@]}"; do
    reuse=()
    for other in "${names[@]}"; do
        [[ $other != "$name" && -d $work/$other/trials ]] && reuse+=(--reuse "$work/$other")
    done
    start=$(date +%s)
    "$work/host" experiment "$here/$name.toml" --out "$work/$name" "${reuse[@]}" || exit 1
    echo "$name: $(($(date +%s) - start)) s wall time in a sitting of $(date -u +%Y-%m-%d) ($(nproc) cores)" >> "$here/$name.wall-time.txt"
    collect
done
