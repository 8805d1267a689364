#!/usr/bin/env bash
# Installs the Debian 12 packages ArucoSLAM builds against (list: DESIGN.md).
# Idempotent: when every package is present it only checks and returns at once.
set -euo pipefail

packages=(
  build-essential cmake pkg-config ccache git
  libopencv-dev libopencv-contrib-dev
  libeigen3-dev libceres-dev libgoogle-glog-dev
  nlohmann-json3-dev libyaml-cpp-dev libcli11-dev libspdlog-dev libfmt-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libsdformat-dev
  libegl-dev libgl-dev libegl-mesa0 libgl1-mesa-dri
  # ROS 1 (Debian's Noetic-era packages): bag input, the arucoslam_ros node, its test's
  # rosmaster and roslaunch. No desktop meta-packages.
  libroscpp-dev librosbag-storage-dev libtf2-ros-dev libimage-transport-dev
  libsensor-msgs-dev libgeometry-msgs-dev libnav-msgs-dev libvisualization-msgs-dev
  libdiagnostic-msgs-dev libtf2-msgs-dev python3-rosmaster python3-roslaunch
)

missing=()
for package in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$package" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$package")
done

if [[ ${#missing[@]} -eq 0 ]]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then
  command -v sudo >/dev/null || { echo "install-deps: need root or sudo to install packages" >&2; exit 1; }
  sudo_cmd=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
