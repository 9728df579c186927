#pragma once

// Private to the engine's NormalEquations*.cpp: the chunk width of the dense elimination kernels.

namespace devsurf::engine::detail {

/// Row stride of the dense elimination buffers: c rounded up to whole chunks, so the kernels
/// (NormalEquationsElimination.cpp) run on fixed-width chunks that the compiler vectorizes (the padding stays zero).
inline constexpr int kChunk = 8;
inline int paddedStride(int c) { return (c + kChunk - 1) / kChunk * kChunk; }

}  // namespace devsurf::engine::detail
