// One policy for image names, wherever they come from (a folder, a model,
// a database) and wherever they go (databases, models, YAML, the live
// page): a name is any non-empty UTF-8 path without control characters.
// A newline or carriage return in a name would split images.txt's lines
// (and COLMAP's), a tab or other control byte shows as nothing in a
// terminal; such files are refused at import, naming them with the bytes
// escaped. Spaces, quotes and non-ASCII letters are kept: databases and
// .bin models store them as they are, our YAML quotes them. images.txt is
// the one place that cannot hold a space: COLMAP 3.8 cuts the name at the
// first one, so a TXT model of such names is refused (BIN keeps them).
#pragma once

#include <string>

namespace portcal {

// "" for an acceptable name; otherwise why not ("is empty", "holds a
// control character (byte 0x0a)").
std::string ImageNameProblem(const std::string& name);

// `name` with control bytes shown as \xNN, for messages.
std::string ShownImageName(const std::string& name);

// Throws InputError "`where`: image name '...' <problem>" for a name
// ImageNameProblem refuses.
void CheckImageName(const std::string& name, const std::string& where);

}  // namespace portcal
