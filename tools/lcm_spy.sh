#!/bin/sh
# Starts lcm-spy with sedbridge's message classes so it decodes our channels.
#   tools/lcm_spy.sh [BUILD_DIR] [--lcm-url=URL]
# Debian's /usr/bin/lcm-spy (LCM 1.3.1) passes -Xincgc, which Java 9+ rejects, so this runs
# lcm.spy.Spy directly. Needs liblcm-java (lcm.jar, jchart2d.jar) and a build that made
# BUILD_DIR/lcmtypes/sedbridge_lcmtypes.jar (CMake builds it when both a JDK and lcm.jar exist).
set -e
root=$(cd "$(dirname "$0")/.." && pwd)
build="$root/build"
case "$1" in --*|"") ;; *) build=$1; shift ;; esac
jar="$build/lcmtypes/sedbridge_lcmtypes.jar"
# Installed tree (PREFIX/share/sedbridge/tools/lcm_spy.sh): the jar is in ../java.
[ -f "$jar" ] || [ ! -f "$root/java/sedbridge_lcmtypes.jar" ] || jar="$root/java/sedbridge_lcmtypes.jar"
lcm_jar=${LCM_JAR:-/usr/share/java/lcm.jar}
[ -f "$lcm_jar" ] || { echo "lcm_spy: $lcm_jar missing (apt install liblcm-java)" >&2; exit 1; }
[ -f "$jar" ] || { echo "lcm_spy: $jar missing (re-run cmake once liblcm-java is installed)" >&2; exit 1; }
cp="$lcm_jar:$jar"
for extra in /usr/share/java/jchart2d.jar; do [ -f "$extra" ] && cp="$cp:$extra"; done
# lcm-spy finds message classes by scanning the jars named in CLASSPATH.
CLASSPATH="$jar" exec java -Djava.net.preferIPv4Stack=true -Xmx128m -cp "$cp" lcm.spy.Spy "$@"
