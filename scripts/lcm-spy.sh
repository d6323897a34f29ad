#!/usr/bin/env bash
# lcm-spy (and lcm-logplayer-gui) with Aerie's message types, on JDK 17.
#
#   scripts/lcm-spy.sh [lcm-spy args]             e.g. --lcm-url "$LCM_DEFAULT_URL"
#   scripts/lcm-logplayer-gui.sh [args] LOG.lcm   (the same script, LogPlayer mode)
#
# Debian 12's /usr/bin/lcm-spy and lcm-logplayer-gui (liblcm-bin 1.3.1) pass
# -Xincgc, which JDK 17 refuses ("Unrecognized option: -Xincgc"); this runs the same
# Java main classes (lcm.spy.Spy, lcm.logging.LogPlayer in /usr/share/java/lcm.jar)
# without it, with Aerie's decoders and lcm-spy's plot library on the class path.
#
# Environment: AERIE_LCMTYPES_JAR (default: build/default/aerie_lcmtypes.jar of this
# checkout), AERIE_LCM_TOOL (spy | logplayer; set by the lcm-logplayer-gui wrapper),
# JAVA (default: java on PATH), JAVA_OPTS (extra JVM options), CLASSPATH (appended).
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(dirname "$here")"
tool="${AERIE_LCM_TOOL:-spy}"
java="${JAVA:-java}"
java_dir=/usr/share/java
lcm_jar="$java_dir/lcm.jar"
types_jar="${AERIE_LCMTYPES_JAR:-$root/build/default/aerie_lcmtypes.jar}"

die() { echo "$(basename "$0"): $*" >&2; exit 1; }

case "$tool" in
  spy) main=lcm.spy.Spy ;;
  logplayer) main=lcm.logging.LogPlayer ;;
  *) die "AERIE_LCM_TOOL must be spy or logplayer, not '$tool'" ;;
esac

command -v "$java" >/dev/null 2>&1 ||
  die "no Java runtime ('$java' not found). Install one: sudo apt-get install default-jre (or run scripts/setup.sh)"
[[ -f "$lcm_jar" ]] ||
  die "$lcm_jar is missing (LCM's Java classes). Install it: sudo apt-get install liblcm-java (or run scripts/setup.sh)"
[[ -f "$types_jar" ]] ||
  die "$types_jar is missing (Aerie's message classes). It is built with the project when a JDK is installed:
  cmake --preset default && cmake --build --preset default --target aerie_lcmtypes_jar
(needs javac: sudo apt-get install default-jdk-headless), or point AERIE_LCMTYPES_JAR at another build's jar."

cp="$lcm_jar:$types_jar"
if [[ "$tool" == spy ]]; then
  # Plots: jchart2d (libjchart2d-java). Its own manifest names its dependencies
  # (jide-oss.jar, xmlgraphics-commons.jar, installed with it); listing those here
  # too would only make lcm-spy's type scanner print errors about their classes.
  if [[ -f "$java_dir/jchart2d.jar" ]]; then
    cp="$cp:$java_dir/jchart2d.jar"
  else
    echo "$(basename "$0"): warning: $java_dir/jchart2d.jar is missing: lcm-spy runs, but its plots do not" \
      "(sudo apt-get install libjchart2d-java, or run scripts/setup.sh)" >&2
  fi
fi
[[ -z "${CLASSPATH:-}" ]] || cp="$cp:$CLASSPATH"

# shellcheck disable=SC2086  # JAVA_OPTS is a list of options
exec "$java" -Djava.net.preferIPv4Stack=true -Xmx256m -ea ${JAVA_OPTS:-} -cp "$cp" "$main" "$@"
