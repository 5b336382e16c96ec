// exr_io.h — OpenEXR input/output of named RGB layers (OpenEXR 3.1).
//
// Layout: the layer with an empty name uses the plain channels R, G, B; every other layer
// "name" uses name.R, name.G, name.B. Written files are 32-bit FLOAT, ZIP compressed,
// scan-line, with data window = display window = [0, w-1] x [0, h-1].
#pragma once

#include <map>
#include <string>
#include <vector>

#include "image/image.h"

namespace gdpt {

struct NamedLayer {
    std::string name;  // "" = default R,G,B channels
    Image image;
};

class StagedFile;

// Writes all layers into one EXR at `path` (staged in a unique temporary file and renamed
// into place, so that a failed write never leaves a half-written file under `path`). All
// layers must have the same non-zero size and distinct names. Throws gdpt::Error naming the
// file and, for I/O failures, the OS's reason.
void writeExr(const std::string& path, const std::vector<NamedLayer>& layers);

// Text attributes stored in an EXR header (name -> value), e.g. the render state that a gdpt
// checkpoint records. Names must not collide with OpenEXR's standard attributes; gdpt uses
// the prefix "gdpt.".
using ExrAttributes = std::map<std::string, std::string>;

// Same, with `attributes` added to the header as string attributes.
void writeExr(const std::string& path, const std::vector<NamedLayer>& layers,
              const ExrAttributes& attributes);

// Convenience: one image into the default R,G,B channels.
void writeExr(const std::string& path, const Image& image);

// Writes the EXR into a staged file of an OutputSet (util/output_files.h); the caller commits.
void writeExr(const StagedFile& file, const std::vector<NamedLayer>& layers,
              const ExrAttributes& attributes = {});

// Reads every layer of a (single-part, flat) EXR. Channels are grouped by the prefix
// before their last '.'; the unprefixed group is the layer "". Within a group:
//   - R, G, B present: used as they are (a missing one of the three reads as 0);
//   - only Y (luminance) present: Y is copied into R, G and B (gray);
//   - other channels (A, Z, ...) are ignored; a group with none of R, G, B, Y is skipped.
// HALF, FLOAT and UINT channels are all converted to float by OpenEXR. The data window may
// have any origin; the returned image covers the data window (its size). Layers come back
// sorted by name, so "" comes first. Throws gdpt::Error naming the file and the problem;
// OpenEXR exceptions (corrupt or truncated files) are caught and wrapped.
std::vector<NamedLayer> readExr(const std::string& path);

// Reads the string attributes of the header (other attribute types are skipped). Throws
// gdpt::Error naming the file for unreadable files, like readExr.
ExrAttributes readExrAttributes(const std::string& path);

// Reads the layer `name` (default: the unnamed R,G,B layer); throws gdpt::Error listing
// the available layers if it is missing.
Image readExrLayer(const std::string& path, const std::string& name = "");

}  // namespace gdpt
