#!/bin/sh
# Rebuilds the measured MEMS records of issue 31's notes from the public
# repository DrTom/spikeprime-pybricks-angular-drift-analysis (commit
# c6a0eeaf828786466fb080284f00baa2e17b7fe9; no licence file, so its data are
# not committed here): LEGO SPIKE Prime / Robot Inventor hubs (ST
# LSM6DS3TR-C IMU) heated by two stalled motors while static, a row every
# 15 s, each the mean of 1000 uncalibrated angular_velocity reads (deg/s).
# Hubs RB and RG have a time column (s since start); RX and TH have none
# and are left out (their row timing is not known).
#
#   docs/notes/issue-31-measured.sh MIRROR_GIT_DIR OUT_DIR
#
# writes OUT_DIR/<hub>_gyro<axis>.csv with t_s,ref_rate_dps,rate_dps,temp_c
# (the hub is static: the reference rate is 0; the Earth rate, < 0.004
# deg/s, is far below this gyro's bias).
set -eu
repo=$1
out=$2
mkdir -p "$out"
for hub in RB RG; do
    git --git-dir="$repo" show "c6a0eeaf828786466fb080284f00baa2e17b7fe9:$hub.csv" |
        awk -F',' -v out="$out" -v hub="$hub" '
        NF >= 6 && $1 ~ /[0-9]/ {
            gsub(/ /, "");
            for (a = 1; a <= 3; a++) {
                f = out "/" hub "_gyro" substr("xyz", a, 1) ".csv";
                if (!(f in seen)) { print "t_s,ref_rate_dps,rate_dps,temp_c" > f; seen[f] = 1 }
                print $1 ",0," $(3 + a) "," $3 >> f;
            }
        }'
done
ls "$out"
