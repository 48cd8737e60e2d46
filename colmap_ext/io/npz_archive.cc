#include "colmap_ext/io/npz_archive.h"

#include <zip.h>

#include <algorithm>
#include <cstring>
#include <memory>
#include <stdexcept>

namespace portcal {
namespace {

std::string ShapeTuple(const std::vector<int64_t>& shape) {
  std::string tuple = "(";
  for (size_t i = 0; i < shape.size(); ++i) tuple += (i ? ", " : "") + std::to_string(shape[i]);
  return tuple + (shape.size() == 1 ? ",)" : ")");
}

int64_t NumValues(const std::vector<int64_t>& shape) {
  int64_t n = 1;
  for (const int64_t s : shape) n *= s;
  return n;
}

template <typename T>
std::string RawBytes(const std::vector<T>& values) {
  // NumPy's '<' descriptors: little-endian, which is this machine's order.
  return std::string(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
}

// The code points of UTF-8 `text`; a byte that starts no valid sequence
// (a Latin-1 file name) becomes U+FFFD, as Python's errors='replace'.
std::vector<uint32_t> CodePoints(const std::string& text) {
  std::vector<uint32_t> points;
  for (size_t i = 0; i < text.size();) {
    const unsigned char lead = static_cast<unsigned char>(text[i]);
    const int length = lead < 0x80           ? 1
                       : (lead >> 5) == 0x6  ? 2
                       : (lead >> 4) == 0xe  ? 3
                       : (lead >> 3) == 0x1e ? 4
                                             : 0;
    uint32_t point = length == 1   ? lead
                     : length == 2 ? lead & 0x1f
                     : length == 3 ? lead & 0x0f
                                   : lead & 0x07;
    bool valid = length > 0 && i + length <= text.size();
    for (int k = 1; valid && k < length; ++k) {
      const unsigned char next = static_cast<unsigned char>(text[i + k]);
      valid = (next & 0xc0) == 0x80;
      point = (point << 6) | (next & 0x3f);
    }
    valid = valid && point <= 0x10ffff && !(point >= 0xd800 && point <= 0xdfff) &&
            !(length == 2 && point < 0x80) && !(length == 3 && point < 0x800) &&
            !(length == 4 && point < 0x10000);
    points.push_back(valid ? point : 0xfffd);
    i += valid ? length : 1;
  }
  return points;
}

// NumPy's '<U<width>': each string as `width` UTF-32LE code units, padded
// with zeros.
std::string Utf32Strings(const std::vector<std::vector<uint32_t>>& values, size_t width) {
  std::vector<uint32_t> units(values.size() * width, 0);
  for (size_t i = 0; i < values.size(); ++i)
    std::copy(values[i].begin(), values[i].end(), units.begin() + i * width);
  return RawBytes(units);
}

[[noreturn]] void ThrowZipError(const std::string& what, zip_error_t* error) {
  const std::string message = what + ": " + zip_error_strerror(error);
  zip_error_fini(error);
  throw std::runtime_error("npz: " + message);
}

}  // namespace

void NpzArchive::Add(const std::string& name, const std::string& descr,
                     const std::vector<int64_t>& shape, const std::string& data) {
  std::string header =
      "{'descr': '" + descr + "', 'fortran_order': False, 'shape': " + ShapeTuple(shape) + ", }";
  // Magic (6) + version (2) + length (2) + header, padded with spaces to a
  // multiple of 64 and ended by a newline.
  const size_t total = 10 + header.size() + 1;
  header.append((64 - total % 64) % 64, ' ');
  header += '\n';
  std::string npy("\x93NUMPY\x01\x00", 8);
  npy += static_cast<char>(header.size() & 0xff);
  npy += static_cast<char>(header.size() >> 8);
  entries_.push_back({name, npy + header + data});
}

template <typename T>
void NpzArchive::AddNumbers(const std::string& name, const std::string& descr,
                            const std::vector<int64_t>& shape, const std::vector<T>& values) {
  if (NumValues(shape) != static_cast<int64_t>(values.size())) {
    throw std::invalid_argument("npz: '" + name + "' has " + std::to_string(values.size()) +
                                " values for shape " + ShapeTuple(shape));
  }
  Add(name, descr, shape, RawBytes(values));
}

void NpzArchive::AddDoubles(const std::string& name, const std::vector<int64_t>& shape,
                            const std::vector<double>& values) {
  AddNumbers(name, "<f8", shape, values);
}

void NpzArchive::AddInt32s(const std::string& name, const std::vector<int64_t>& shape,
                           const std::vector<int32_t>& values) {
  AddNumbers(name, "<i4", shape, values);
}

void NpzArchive::AddBool(const std::string& name, bool value) {
  Add(name, "|b1", {}, std::string(1, value ? '\x01' : '\x00'));
}

void NpzArchive::AddString(const std::string& name, const std::string& value) {
  const std::vector<uint32_t> points = CodePoints(value);
  const size_t width = std::max<size_t>(1, points.size());
  Add(name, "<U" + std::to_string(width), {}, Utf32Strings({points}, width));
}

void NpzArchive::AddStrings(const std::string& name, const std::vector<std::string>& values) {
  std::vector<std::vector<uint32_t>> points;
  size_t width = 1;
  for (const std::string& value : values) {
    points.push_back(CodePoints(value));
    width = std::max(width, points.back().size());
  }
  Add(name, "<U" + std::to_string(width), {static_cast<int64_t>(values.size())},
      Utf32Strings(points, width));
}

std::string NpzArchive::Bytes() const {
  zip_error_t error;
  zip_error_init(&error);
  zip_source_t* buffer = zip_source_buffer_create(nullptr, 0, 0, &error);
  if (!buffer) ThrowZipError("creating the buffer", &error);
  zip_t* archive = zip_open_from_source(buffer, ZIP_TRUNCATE, &error);
  if (!archive) {
    zip_source_free(buffer);
    ThrowZipError("opening the archive", &error);
  }
  zip_source_keep(buffer);  // read back after zip_close
  const auto fail = [&](const std::string& what) {
    const std::string message = std::string("npz: ") + what + ": " + zip_strerror(archive);
    zip_discard(archive);
    zip_source_free(buffer);
    throw std::runtime_error(message);
  };
  for (const Entry& entry : entries_) {
    zip_source_t* source = zip_source_buffer(archive, entry.npy.data(), entry.npy.size(), 0);
    if (!source) fail("adding " + entry.name);
    const zip_int64_t index =
        zip_file_add(archive, (entry.name + ".npy").c_str(), source, ZIP_FL_ENC_UTF_8);
    if (index < 0) {
      zip_source_free(source);
      fail("adding " + entry.name);
    }
    if (zip_set_file_compression(archive, index, ZIP_CM_DEFLATE, 0) != 0)
      fail("compressing " + entry.name);
  }
  if (zip_close(archive) != 0) fail("writing the archive");
  std::string bytes;
  if (zip_source_open(buffer) != 0 || zip_source_seek(buffer, 0, SEEK_END) != 0) {
    zip_source_free(buffer);
    throw std::runtime_error("npz: reading the archive back");
  }
  bytes.resize(static_cast<size_t>(zip_source_tell(buffer)));
  zip_source_seek(buffer, 0, SEEK_SET);
  const zip_int64_t read = zip_source_read(buffer, bytes.data(), bytes.size());
  zip_source_close(buffer);
  zip_source_free(buffer);
  if (read != static_cast<zip_int64_t>(bytes.size()))
    throw std::runtime_error("npz: short read of the archive");
  return bytes;
}

std::string EncodeBase85(const std::string& bytes) {
  static const char kAlphabet[] =
      "0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz!#$%&()*+-;<=>?@^_`{|}~";
  const size_t padding = (4 - bytes.size() % 4) % 4;
  std::string padded = bytes + std::string(padding, '\0');
  std::string out;
  out.reserve(padded.size() / 4 * 5);
  for (size_t i = 0; i < padded.size(); i += 4) {
    uint32_t word = 0;
    for (int k = 0; k < 4; ++k) word = (word << 8) | static_cast<unsigned char>(padded[i + k]);
    char group[5];
    for (int k = 4; k >= 0; --k) {
      group[k] = kAlphabet[word % 85];
      word /= 85;
    }
    out.append(group, 5);
  }
  out.resize(out.size() - padding);
  return out;
}

}  // namespace portcal
