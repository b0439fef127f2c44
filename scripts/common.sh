# Shared by scripts/test and scripts/demo: dependency install and build. Source it, do not run it.
# shellcheck shell=bash

MAF_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
MAF_BUILD="${MAF_BUILD:-$MAF_ROOT/build}"
# The package's executables (rosrun does not look under <package>/build, where these scripts build).
MAF_BIN="$MAF_BUILD/devel/lib/map_aided_fusion"
# Debian's ROS Python modules live in /usr/bin/python3, not in a pyenv or virtualenv python.
export PATH="/usr/bin:/bin:/usr/sbin:/sbin:$PATH"
export PYTHONNOUSERSITE=1

# Debian 12 packages the build, the tests, the benchmarks and the demo need.
MAF_DEB_PACKAGES=(
  build-essential cmake catkin pkg-config
  libroscpp-dev libnodeletlib-dev libnodelet-dev libnodeletlib-tools pluginlib-dev
  libtf2-ros-dev libtf2-dev libtf2-geometry-msgs-dev libtf2-msgs-dev
  libsensor-msgs-dev libnav-msgs-dev libvisualization-msgs-dev libgeometry-msgs-dev libstd-msgs-dev
  libstd-srvs-dev libdiagnostic-updater-dev libdynamic-reconfigure-config-init-mutex-dev
  ros-message-generation ros-message-runtime librosbag-dev python3-rosbag
  librostest-dev python3-rostest python3-roslaunch rosbash
  python3-sensor-msgs python3-nav-msgs python3-visualization-msgs python3-geometry-msgs python3-std-msgs
  python3-std-srvs python3-dynamic-reconfigure python3-tf2-msgs python3-diagnostic-msgs
  ros-std-msgs ros-nav-msgs ros-geometry-msgs ros-sensor-msgs ros-visualization-msgs ros-std-srvs
  libeigen3-dev libgeographiclib-dev libgdal-dev libyaml-cpp-dev
  libgtest-dev libbenchmark-dev
  libpcl-dev libpcl-ros-dev libpcl-ros-filters0d libpcl-ros-filter1d tf2-tools
  libtbb-dev python3-yaml python3-optuna python3-psycopg2 python3-pytest postgresql catkin-lint
  python3-rospy python3-tf2-ros python3-numpy
)

maf_log() { printf '\033[1m[map_aided_fusion]\033[0m %s\n' "$*" >&2; }

maf_install_deps() {
  local missing=()
  local p
  for p in "${MAF_DEB_PACKAGES[@]}" "$@"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q '^install ok installed$'; then
      missing+=("$p")
    fi
  done
  if [ ${#missing[@]} -eq 0 ]; then
    return 0
  fi
  maf_log "installing ${#missing[@]} Debian packages: ${missing[*]}"
  local sudo=()
  if [ "$(id -u)" -ne 0 ]; then sudo=(sudo); fi
  "${sudo[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

maf_build() {
  mkdir -p "$MAF_BUILD"
  if [ ! -f "$MAF_BUILD/CMakeCache.txt" ]; then
    cmake -S "$MAF_ROOT" -B "$MAF_BUILD" -DCMAKE_BUILD_TYPE=Release \
      -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 -DCATKIN_ENABLE_TESTING=ON >"$MAF_BUILD/configure.log" 2>&1 || {
      cat "$MAF_BUILD/configure.log" >&2
      return 1
    }
  fi
  make -C "$MAF_BUILD" -j"$(nproc)" --no-print-directory "$@"
}

maf_source_devel() {
  # shellcheck disable=SC1091
  set +u
  source "$MAF_BUILD/devel/setup.bash"
  set -u
}
