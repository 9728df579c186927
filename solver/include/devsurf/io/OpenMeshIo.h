#pragma once

#include <mutex>

namespace devsurf::io {

/// The lock to hold around every OpenMesh `read_mesh` and `write_mesh`.
///
/// OpenMesh reads and writes every file through one reader and one writer object per format for
/// the whole process (its IOManager), and several of them keep the file at hand in members: the
/// PLY reader its elements, counts and options, the OFF reader its options, the OBJ writer its
/// path and materials. The daemon reads uploaded shapes and writes exports on several route
/// workers at once; without the lock, two threads reading and writing PLY, OFF and OBJ files at
/// once ended the process with a segmentation fault (QuadMesh.FilesReadAndWrittenOnTwoThreadsAtOnce…).
std::mutex& openMeshIoMutex();

}  // namespace devsurf::io
