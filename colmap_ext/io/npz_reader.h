// Reading NumPy's .npz archives (numpy.savez / savez_compressed), as mrcal
// stores a calibration's optimization_inputs in a .cameramodel: base 85
// text of a zip of .npy arrays. The input may be hostile (a .cameramodel
// from anywhere), so sizes are bounded before anything is inflated, every
// header is checked against its data, and pickled objects are refused (as
// mrcal itself loads them: allow_pickle=False).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace portcal {

// One array, its data in C order whatever order the file stored.
struct NpyArray {
  std::string descr;           // NumPy's type string, e.g. "<f8", "|b1", "<U17"
  std::vector<int64_t> shape;  // empty for a scalar
  std::string data;            // little-endian values, size() * item size bytes

  int64_t size() const;  // the number of values (1 for a scalar)
  // The values of a numeric or boolean array as doubles / integers
  // (integers: not from floating point). Throw InputError naming
  // `context` and the type otherwise.
  std::vector<double> Doubles(const std::string& context) const;
  std::vector<int64_t> Integers(const std::string& context) const;
  // The strings of a '<U' array, as UTF-8 (code points that are not
  // Unicode throw InputError).
  std::vector<std::string> Strings(const std::string& context) const;
  // mrcal's None: a scalar empty string.
  bool IsNone() const;
};

// The arrays of an .npz archive by name (without ".npy"). Throws InputError
// prefixed by `context` for anything that is not a well-formed archive of
// at most 10 000 arrays and 256 MiB inflated.
std::map<std::string, NpyArray> ReadNpz(const std::string& bytes, const std::string& context);

// Python's base64.b85decode (RFC 1924's alphabet). Throws InputError
// prefixed by `context` on a character outside the alphabet or a group
// that overflows 32 bits.
std::string DecodeBase85(const std::string& text, const std::string& context);

}  // namespace portcal
