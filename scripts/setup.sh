#!/usr/bin/env bash
# Installs every Debian package the project needs (idempotent; root on Debian 12).
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
PACKAGES=(
  catkin libroscpp-dev libnodeletlib-dev libnodeletlib-tools
  libtf2-dev libtf2-ros-dev libtf2-geometry-msgs-dev libtf2-eigen-dev libcv-bridge-dev
  libimage-transport-dev libimage-geometry-dev libsensor-msgs-dev libgeometry-msgs-dev
  libstd-msgs-dev libstd-srvs-dev libvisualization-msgs-dev ros-sensor-msgs ros-geometry-msgs
  ros-std-msgs ros-message-generation ros-message-runtime liburdf-dev libresource-retriever-dev
  libdynamic-reconfigure-config-init-mutex-dev python3-dynamic-reconfigure
  libdiagnostic-updater-dev python3-rosservice python3-std-srvs
  librostest-dev python3-rostest librosbag-dev python3-rosbag python3-roslaunch
  python3-rosmaster rosout python3-rostopic python3-rosnode rosbash
  python3-geometry-msgs python3-sensor-msgs python3-tf2-msgs
  libgtest-dev libopencv-dev libeigen3-dev libnlopt-cxx-dev libassimp-dev libmeshoptimizer-dev
  opencv-doc cmake g++ make
  clang libfuzzer-14-dev libclang-rt-14-dev
)
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  log "setup: all ${#PACKAGES[@]} Debian packages already installed"
else
  log "setup: installing ${#missing[@]} Debian packages: ${missing[*]}"
  if [ "$(id -u)" -ne 0 ]; then echo "setup: run as root to install packages" >&2; exit 1; fi
  export DEBIAN_FRONTEND=noninteractive
  apt-get update
  apt-get install -y --no-install-recommends -o DPkg::Lock::Timeout=600 "${missing[@]}"
fi
# opencv-doc ships the real photographs used as backgrounds; some images exclude /usr/share/doc.
if [ ! -f /usr/share/doc/opencv-doc/examples/data/graf1.png ]; then
  echo "setup: /usr/share/doc/opencv-doc/examples/data is missing (a dpkg path-exclude for" \
       "/usr/share/doc?). The data generator falls back to a synthetic background." >&2
fi
