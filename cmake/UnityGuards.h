#pragma once
// Included first in every test and server translation unit (CMake: -include for the server, the
// tests' shared precompiled header begins with it, tests/CMakeLists.txt): they are compiled in
// unity batches, and <resolv.h> (pulled in by cpp-httplib) defines the macro `_res`, which breaks
// Eigen headers parsed later in the same batch (Eigen names a parameter `_res`). Including it here
// and undefining the macro makes the batch order irrelevant; nothing in devsurf uses `_res`.
#include <resolv.h>
#undef _res
