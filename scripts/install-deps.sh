#!/usr/bin/env bash
# Installs the Debian 12 packages Frac needs, only those that are missing.
set -euo pipefail
packages=(build-essential cmake pkg-config libfmt-dev catch2 libcli11-dev libeigen3-dev libgmp-dev
          libpng-dev libmpfr-dev libmpfi-dev libtbb-dev llvm-19-dev libllvmlibc-19-dev clang-format
          libosd-dev libceres-dev libjpeg62-turbo-dev xplanet-images zlib1g-dev python-matplotlib-data
          libmimalloc-dev libzstd-dev)
# --fuzz: also clang-19 and its libFuzzer run time, for `make fuzz` only (the build uses the default compiler).
if [ "${1:-}" = "--fuzz" ]; then packages+=(clang-19 libclang-rt-19-dev); fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then exit 0; fi
echo "installing: ${missing[*]}" >&2
sudo_cmd=""
if [ "$(id -u)" -ne 0 ]; then sudo_cmd="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$sudo_cmd apt-get update -qq
$sudo_cmd apt-get install -y -qq --no-install-recommends "${missing[@]}"
