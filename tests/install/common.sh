# SPDX-License-Identifier: Apache-2.0
# Sourced by the install tests: a temporary directory removed at exit with every process the test started,
# fail(), and Cyclone DDS on loopback only (1 s lease: a stopped daemon is noticed soon).
tmp=$(mktemp -d "${TMPDIR:-/tmp}/cellmap-install-XXXXXX")
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill -KILL "$pid" 2>/dev/null || true; done
  rm -rf "$tmp"
}
trap cleanup EXIT
fail() {
  echo "FAIL: $*" >&2
  exit 1
}
export CYCLONEDDS_URI='<CycloneDDS><Domain Id="any"><General><Interfaces><NetworkInterface address="127.0.0.1"/></Interfaces><AllowMulticast>false</AllowMulticast></General><Discovery><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>30</MaxAutoParticipantIndex><Peers><Peer address="127.0.0.1"/></Peers><LeaseDuration>1 s</LeaseDuration></Discovery></Domain></CycloneDDS>'
