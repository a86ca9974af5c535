# Debian 12 packages, installed by scripts/install-deps.sh.
find_package(fmt REQUIRED)
find_package(Catch2 2 REQUIRED)
find_package(CLI11 REQUIRED)
find_package(PNG REQUIRED)
find_package(PkgConfig REQUIRED)
find_package(TBB REQUIRED) # parallel subdivision
find_package(Eigen3 3.3 REQUIRED NO_MODULE) # eigenpairs of subdivision operators (runtime/automata/analysis)
find_package(Ceres REQUIRED) # Levenberg-Marquardt fitting of projected IFS (runtime/fit)
find_package(JPEG REQUIRED) # the JPEG side of the fitting benchmark (bench/bench_fit.cpp)
find_package(ZLIB REQUIRED) # the fitting benchmark reads the .npz of a real elevation model

# LLVM's libc: correctly rounded exp/log/sin/cos/tan that honour the current rounding mode.
find_library(LLVMLIBC_ARCHIVE llvmlibc PATHS /usr/lib/llvm-19/lib NO_DEFAULT_PATH REQUIRED)
# GMP (gmpxx): exact rationals in the numeric layer; MPFR: their directed rounding to doubles.
# MPFI: high-precision oracle for the soundness tests only.
find_library(MPFR_LIBRARY mpfr REQUIRED)
find_library(MPFI_LIBRARY mpfi REQUIRED)
find_library(GMP_LIBRARY gmp REQUIRED)
find_library(GMPXX_LIBRARY gmpxx REQUIRED)
