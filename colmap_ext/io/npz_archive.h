// NumPy's .npz archives (a zip of .npy arrays, as numpy.savez_compressed
// writes them), built in memory: mrcal keeps a calibration's
// optimization_inputs in a .cameramodel as such an archive, base-85
// encoded. The zip container is libzip's; the .npy headers follow NumPy's
// format 1.0 (a dict literal padded to a multiple of 64 bytes).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace portcal {

class NpzArchive {
 public:
  // Arrays in C order; `shape` empty for a scalar (then one value).
  void AddDoubles(const std::string& name, const std::vector<int64_t>& shape,
                  const std::vector<double>& values);
  void AddInt32s(const std::string& name, const std::vector<int64_t>& shape,
                 const std::vector<int32_t>& values);
  void AddDouble(const std::string& name, double value) { AddDoubles(name, {}, {value}); }
  void AddBool(const std::string& name, bool value);
  // A scalar string, or a 1-D array of them (NumPy's '<U' strings: UTF-32,
  // from UTF-8; invalid bytes become U+FFFD).
  void AddString(const std::string& name, const std::string& value);
  void AddStrings(const std::string& name, const std::vector<std::string>& values);

  // The deflated zip. Throws std::runtime_error when libzip fails.
  std::string Bytes() const;

 private:
  struct Entry {
    std::string name;  // without ".npy"
    std::string npy;   // header and data
  };
  void Add(const std::string& name, const std::string& descr, const std::vector<int64_t>& shape,
           const std::string& data);
  template <typename T>
  void AddNumbers(const std::string& name, const std::string& descr,
                  const std::vector<int64_t>& shape, const std::vector<T>& values);
  std::vector<Entry> entries_;
};

// Base 85 with Python's alphabet (base64.b85encode: RFC 1924's characters),
// 4 bytes to 5 characters, a short last group padded and cut as Python does.
std::string EncodeBase85(const std::string& bytes);

}  // namespace portcal
