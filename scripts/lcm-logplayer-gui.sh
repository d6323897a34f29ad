#!/usr/bin/env bash
# lcm-logplayer-gui with Aerie's message types, on JDK 17 (see scripts/lcm-spy.sh).
#   scripts/lcm-logplayer-gui.sh [--lcm-url URL] logs/flight-....lcm
AERIE_LCM_TOOL=logplayer exec "$(dirname "${BASH_SOURCE[0]}")/lcm-spy.sh" "$@"
