#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "devsurf/io/QuadMesh.h"

namespace devsurf::server {

/// Options of a surface thumbnail.
struct ThumbnailOptions {
  int width = 320;     ///< pixels, in [16, 2048]
  int height = 240;    ///< pixels, in [16, 2048]
  int supersampling = 3;  ///< samples per pixel along each axis, in [1, 4] (box-filtered)
  double margin = 0.06;   ///< blank border, as a fraction of the smaller side, in [0, 0.4]
};

/// An RGBA picture, rows top to bottom, 8 bits per channel.
struct ThumbnailImage {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;  ///< width·height·4 bytes
};

/// A small picture of a sampled surface (the background transparent, alpha 0, so the page's
/// colour shows; edge pixels partly covered).
///
/// View: orthographic, along d = normalize(e3 + 0.55·e2 + 0.35·e1) from the principal axes of the
/// vertices (e1 the longest; e1, e2 pointing towards the vertices' larger third moment, e3 to the
/// side the area-weighted normals point to, so the viewer sees the front); screen x is e1 projected, y completes
/// a right-handed frame with d. The drawing is centred and scaled to fill the picture up to the
/// margin, aspect kept. Triangles (io::triangulateQuads) are filled with a z-buffer and flat
/// Lambert shading lit from the viewer's upper left, both sides alike; front and back faces get
/// two tints of the app's surface colours (front blue, back orange). The work is bounded: when the
/// triangles' bounding boxes add up to more than 6.4e7 samples, fewer samples per pixel are taken,
/// and a surface whose boxes cover more than that at one sample per pixel (833 pictures' worth of
/// overlapping triangles) is refused.
/// @throws std::invalid_argument for bad options or a surface without vertices or triangles,
///         std::runtime_error if libpng fails.
ThumbnailImage renderSurfaceThumbnail(const io::QuadMesh& surface, const ThumbnailOptions& options = {});

/// The picture as PNG bytes (libpng, colour type RGBA, 8 bits).
/// @throws std::invalid_argument for a size that does not match, std::runtime_error if libpng fails.
std::string pngBytes(const ThumbnailImage& image);

/// pngBytes(renderSurfaceThumbnail(surface, options)).
std::string surfaceThumbnailPng(const io::QuadMesh& surface, const ThumbnailOptions& options = {});

}  // namespace devsurf::server
