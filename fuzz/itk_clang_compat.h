// Debian's ITK 5.2 ships a compiler-detection header generated for GCC only: under clang it
// stops with "Unsupported compiler". The fuzz build (clang, for libFuzzer) force-includes this
// file (-include) into src/io: ITK's header runs once here, seeing GCC 5.0's identity (clang 14
// has every C++ feature it tests for), and its include guard keeps ITK's own #include of it from
// running the detection again. The real macros come back right after it.
#pragma push_macro("__clang__")
#pragma push_macro("__GNUC__")
#pragma push_macro("__GNUC_MINOR__")
#undef __clang__
#undef __GNUC__
#undef __GNUC_MINOR__
#define __GNUC__ 5
#define __GNUC_MINOR__ 0
#include <itk_compiler_detection.h>
#pragma pop_macro("__GNUC_MINOR__")
#pragma pop_macro("__GNUC__")
#pragma pop_macro("__clang__")
