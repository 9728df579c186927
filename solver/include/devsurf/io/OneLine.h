#pragma once

#include <string>
#include <string_view>

namespace devsurf::io {

/// `text` as one line for a file's comment or title (OBJ's "#", DXF's 999, a header): every
/// control character (C0, DEL) becomes a space, so a name with a newline cannot start a record
/// of its own (a scene named "part\nv 1 1 1" added a vertex to its OBJ).
std::string oneLine(std::string_view text);

}  // namespace devsurf::io
