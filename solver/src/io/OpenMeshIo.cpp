#include "devsurf/io/OpenMeshIo.h"

namespace devsurf::io {

std::mutex& openMeshIoMutex() {
  static std::mutex mutex;
  return mutex;
}

}  // namespace devsurf::io
