// Private to the numeric core: LLVM libc's correctly rounded double functions.
//
// They honour the current rounding mode, so under UpwardRounding each returns RU(f(x)), the smallest
// double >= f(x). They live in a versioned C++ namespace (e.g. __llvm_libc_19_1_7_); CMake reads the
// name from the archive and defines FRAC_LLVMLIBC_NAMESPACE. We link a copy of the archive in which only
// these namespaced symbols stay global, so its plain C symbols (sin, cos, memcpy, ...) cannot preempt
// glibc's for the rest of the program.
#pragma once

#ifndef FRAC_LLVMLIBC_NAMESPACE
#error "FRAC_LLVMLIBC_NAMESPACE must name LLVM libc's namespace (set by numeric/CMakeLists.txt)"
#endif

namespace FRAC_LLVMLIBC_NAMESPACE {
double sin(double x);
double cos(double x);
double tan(double x);
double exp(double x);
double log(double x);
} // namespace FRAC_LLVMLIBC_NAMESPACE

namespace frac::num {
namespace crlibm = FRAC_LLVMLIBC_NAMESPACE;
} // namespace frac::num
