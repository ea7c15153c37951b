#!/bin/bash
# Instructions per step of the FMU with mu fixed, with a new mu every step, with a
# step varying +-2 % (the Taylor step of the remainder) and per frame (inputs set,
# step, outputs read), from valgrind's callgrind (counts, not times: independent of
# the machine's load).
#
#   bench/fmu_mu_callgrind.sh FILE.fmu [N1 N2]
#
# Runs bench/fmu_mu_loop.c at N1 and N2 steps (default 20000 and 60000) in each mode
# (and mode 4: a new mu every step, each in another of the table's parts) and prints
# the difference per step (the start-up and the first table build cancel), then the
# mu-every-step instructions per step by function.  Results: bench/fmu_states.md.
set -euo pipefail
fmu=$(realpath "$1"); n1=${2:-20000}; n2=${3:-60000}
here=$(cd "$(dirname "$0")" && pwd)
d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
cd "$d"
unzip -q "$fmu"
so=$(ls "$d"/binaries/linux64/*.so)
guid=$(grep -o 'guid="[^"]*"' modelDescription.xml | head -1 | cut -d'"' -f2)
gcc -O2 -I"$here/../fmu" "$here/fmu_mu_loop.c" -ldl -o loop
per_step() {   # mode -> instructions per step
    local mode=$1 n
    for n in $n1 $n2; do
        valgrind --tool=callgrind --callgrind-out-file=cg.$mode.$n ./loop "$so" "$guid" $n \
            $mode >/dev/null 2>log.$mode.$n
    done
    echo $(( ($(grep -o "Collected : [0-9]*" log.$mode.$n2 | awk '{print $3}') -
              $(grep -o "Collected : [0-9]*" log.$mode.$n1 | awk '{print $3}')) / (n2 - n1) ))
}
fixed=$(per_step 0); varying=$(per_step 1); remainder=$(per_step 2); frame=$(per_step 3)
across=$(per_step 4)
echo "$(basename "$fmu"): mu every step $varying, mu fixed $fixed instructions per step" \
     "(ratio $(awk "BEGIN {printf \"%.2f\", $varying / $fixed}")); step varying +-2 %" \
     "$remainder; frame $frame; mu every step across the table's parts $across"
for n in $n1 $n2; do
    callgrind_annotate cg.1.$n 2>/dev/null |
        awk '{gsub(",", "", $1); for (i = 2; i <= NF; i++) if ($i ~ /^[?][?][?]:/) print $i, $1}' |
        sort > f.$n
done
join -a2 -e0 -o 0,1.2,2.2 f.$n1 f.$n2 |
    awk -v dn=$((n2 - n1)) '{d = ($3 - $2) / dn; if (d >= 1) printf "  %-40s %5.0f\n", substr($1, 5), d}'
