# Sourced by the tests that run against the wall clock (a simulator publishing in real time, a script waiting
# until the robot is somewhere). ADIT_TEST_TIME_SCALE (ctest sets it, 4 in sanitized builds: CMakeLists.txt)
# slows the simulated world down so that stages several times slower still keep up:
#   RATE       the simulator's multiple of real time (exported; launch files pass ${RATE:-1} to --rate)
#   scaled S   S seconds of the simulated world in wall time
TIME_SCALE=${ADIT_TEST_TIME_SCALE:-1}
RATE=$(awk -v s="$TIME_SCALE" 'BEGIN { printf "%g", 1 / s }')
export RATE
scaled() { awk -v t="$1" -v s="$TIME_SCALE" 'BEGIN { printf "%g", t * s }'; }
