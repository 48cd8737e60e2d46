// Paths that come from data -- an image's name in a database, a model or a
// request -- kept inside the folder they are meant for, and output files
// kept off the inputs and off anything that is not a regular file: a
// hostile or careless name must not make a stage write, rename or
// overwrite anything else.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace portcal {

// `folder` / `name`, where `name` is relative, has no ".." component, no
// NUL or control character, and (resolving the symbolic links that exist
// already) stays inside `folder`; what already exists there must be a
// regular file. Throws InputError naming `what` (e.g. "image name in
// model/images.txt") and the name otherwise.
std::filesystem::path ConfinedPath(const std::filesystem::path& folder, const std::string& name,
                                   const std::string& what);

// For Options::Check(): an output file (`option`'s value) that is one of
// `inputs` (the same file, by any path) or exists and is not a regular file
// (a device, a folder, a fifo) is an OptionError naming `option`.
void CheckOutputFile(const std::string& option, const std::string& output,
                     const std::vector<std::string>& inputs);

}  // namespace portcal
