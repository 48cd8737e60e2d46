#include "colmap_ext/io/npz_reader.h"

#include <zip.h>

#include <array>
#include <cctype>
#include <cstring>
#include <limits>
#include <memory>

#include "colmap_ext/util/error.h"

namespace portcal {
namespace {

constexpr int64_t kMaxArrays = 10000;
constexpr uint64_t kMaxInflatedBytes = uint64_t{256} << 20;

struct ZipCloser {
  void operator()(zip_t* archive) const { zip_discard(archive); }
};
struct ZipFileCloser {
  void operator()(zip_file_t* file) const { zip_fclose(file); }
};

// The item's kind ('f', 'i', 'u', 'b', 'U') and size in bytes; throws for
// what is not read here (big-endian, complex, objects, structured types).
std::pair<char, size_t> ItemType(const std::string& descr, const std::string& context) {
  const auto fail = [&] {
    throw InputError(context + ": array type '" + descr +
                     "' is not read (little-endian numbers, booleans "
                     "and '<U' strings are; pickled objects are refused)");
  };
  if (descr.size() < 3 || (descr[0] != '<' && descr[0] != '|')) fail();
  const char kind = descr[1];
  size_t size = 0;
  for (size_t i = 2; i < descr.size(); ++i) {
    if (!std::isdigit(static_cast<unsigned char>(descr[i])) || size > 100000) fail();
    size = size * 10 + static_cast<size_t>(descr[i] - '0');
  }
  const bool ok =
      (kind == 'f' && (size == 4 || size == 8)) ||
      ((kind == 'i' || kind == 'u') && (size == 1 || size == 2 || size == 4 || size == 8)) ||
      (kind == 'b' && size == 1) || (kind == 'U' && size >= 1);
  if (!ok) fail();
  return {kind, kind == 'U' ? 4 * size : size};
}

// The value of `key` in an .npy header (a Python dict literal), up to the
// next comma outside brackets or quotes.
std::string HeaderValue(const std::string& header, const std::string& key,
                        const std::string& context) {
  size_t at = header.find("'" + key + "'");
  if (at == std::string::npos) throw InputError(context + ": .npy header without '" + key + "'");
  at = header.find(':', at);
  if (at == std::string::npos) throw InputError(context + ": malformed .npy header");
  size_t end = at + 1;
  int depth = 0;
  char quote = 0;
  for (; end < header.size(); ++end) {
    const char c = header[end];
    if (quote) {
      if (c == quote) quote = 0;
    } else if (c == '\'' || c == '"') {
      quote = c;
    } else if (c == '(' || c == '[') {
      ++depth;
    } else if (c == ')' || c == ']') {
      --depth;
    } else if ((c == ',' && depth == 0) || c == '}') {
      break;
    }
  }
  std::string value = header.substr(at + 1, end - at - 1);
  const size_t first = value.find_first_not_of(" \t");
  const size_t last = value.find_last_not_of(" \t");
  return first == std::string::npos ? "" : value.substr(first, last - first + 1);
}

std::vector<int64_t> ParseShape(const std::string& text, const std::string& context) {
  if (text.size() < 2 || text.front() != '(' || text.back() != ')') {
    throw InputError(context + ": .npy shape '" + text + "' is not a tuple");
  }
  std::vector<int64_t> shape;
  int64_t value = -1;
  for (size_t i = 1; i + 1 < text.size(); ++i) {
    const char c = text[i];
    if (std::isdigit(static_cast<unsigned char>(c))) {
      value = (value < 0 ? 0 : value) * 10 + (c - '0');
      if (value > std::numeric_limits<int32_t>::max())
        throw InputError(context + ": .npy dimension too large");
    } else if (c == ',') {
      if (value < 0) throw InputError(context + ": .npy shape '" + text + "' is malformed");
      shape.push_back(value);
      value = -1;
    } else if (c != ' ' && c != 'L') {
      throw InputError(context + ": .npy shape '" + text + "' is malformed");
    }
  }
  if (value >= 0) shape.push_back(value);
  if (shape.size() > 32) throw InputError(context + ": .npy array of more than 32 dimensions");
  return shape;
}

// Fortran order to C order, item by item.
std::string ToCOrder(const std::string& data, const std::vector<int64_t>& shape, size_t item) {
  std::string out(data.size(), '\0');
  const int64_t n = static_cast<int64_t>(data.size() / item);
  std::vector<int64_t> index(shape.size(), 0);
  for (int64_t c = 0; c < n; ++c) {
    int64_t f = 0, stride = 1;
    for (size_t d = 0; d < shape.size(); ++d) {
      f += index[d] * stride;
      stride *= shape[d];
    }
    std::memcpy(&out[static_cast<size_t>(c) * item], &data[static_cast<size_t>(f) * item], item);
    for (size_t d = shape.size(); d-- > 0;) {  // the last index runs fastest in C order
      if (++index[d] < shape[d]) break;
      index[d] = 0;
    }
  }
  return out;
}

NpyArray ParseNpy(const std::string& npy, const std::string& context) {
  if (npy.size() < 10 || npy.compare(0, 6, "\x93NUMPY") != 0)
    throw InputError(context + ": not an .npy array");
  const int major = static_cast<unsigned char>(npy[6]);
  size_t header_length = 0, start = 0;
  if (major == 1) {
    header_length = static_cast<unsigned char>(npy[8]) |
                    (static_cast<size_t>(static_cast<unsigned char>(npy[9])) << 8);
    start = 10;
  } else if ((major == 2 || major == 3) && npy.size() >= 12) {
    for (int k = 3; k >= 0; --k)
      header_length = (header_length << 8) | static_cast<unsigned char>(npy[8 + k]);
    start = 12;
  } else {
    throw InputError(context + ": .npy format version " + std::to_string(major) + " is not read");
  }
  if (header_length > npy.size() - start)
    throw InputError(context + ": .npy header runs past the array");
  const std::string header = npy.substr(start, header_length);
  NpyArray array;
  const std::string descr = HeaderValue(header, "descr", context);
  if (descr.size() < 2 || (descr.front() != '\'' && descr.front() != '"') ||
      descr.back() != descr.front()) {
    throw InputError(context + ": .npy type " + descr + " is not read (structured arrays are not)");
  }
  array.descr = descr.substr(1, descr.size() - 2);
  const size_t item = ItemType(array.descr, context).second;
  const std::string order = HeaderValue(header, "fortran_order", context);
  if (order != "False" && order != "True")
    throw InputError(context + ": .npy fortran_order '" + order + "'");
  array.shape = ParseShape(HeaderValue(header, "shape", context), context);
  const size_t data_size = npy.size() - start - header_length;
  uint64_t count = 1;
  for (const int64_t dim : array.shape) {
    if (dim != 0 && count > data_size / static_cast<uint64_t>(dim)) {
      throw InputError(context + ": .npy shape larger than its data");
    }
    count *= static_cast<uint64_t>(dim);
  }
  if (count * item != data_size) {
    throw InputError(context + ": .npy data of " + std::to_string(data_size) + " bytes for " +
                     std::to_string(count) + " values of " + std::to_string(item) + " bytes");
  }
  array.data = npy.substr(start + header_length);
  if (order == "True" && array.shape.size() > 1)
    array.data = ToCOrder(array.data, array.shape, item);
  return array;
}

template <typename T>
T LoadAt(const std::string& data, size_t index) {
  T value;
  std::memcpy(&value, data.data() + index * sizeof(T),
              sizeof(T));  // little-endian, as this machine
  return value;
}

// The inflated bytes of entry `index`, at most `budget` of them.
std::string ReadEntry(zip_t* archive, zip_uint64_t index, uint64_t* budget,
                      const std::string& context) {
  zip_stat_t stat;
  zip_stat_init(&stat);
  if (zip_stat_index(archive, index, 0, &stat) != 0 || !(stat.valid & ZIP_STAT_SIZE)) {
    throw InputError(context + ": unreadable zip entry " + std::to_string(index));
  }
  if (stat.size > *budget) {
    throw InputError(context + ": the archive inflates to more than " +
                     std::to_string(kMaxInflatedBytes >> 20) + " MiB");
  }
  *budget -= stat.size;
  std::unique_ptr<zip_file_t, ZipFileCloser> file(zip_fopen_index(archive, index, 0));
  if (!file)
    throw InputError(context + ": cannot open zip entry " + std::to_string(index) + ": " +
                     zip_strerror(archive));
  std::string bytes(stat.size, '\0');
  char extra;
  // libzip checks the CRC at the end of the entry: a short or long read, or
  // a mismatch, is an error.
  if (zip_fread(file.get(), bytes.data(), stat.size) != static_cast<zip_int64_t>(stat.size) ||
      zip_fread(file.get(), &extra, 1) != 0) {
    throw InputError(context + ": zip entry " + std::to_string(index) + " is damaged");
  }
  return bytes;
}

}  // namespace

int64_t NpyArray::size() const {
  int64_t n = 1;
  for (const int64_t dim : shape) n *= dim;
  return n;
}

std::vector<double> NpyArray::Doubles(const std::string& context) const {
  const auto [kind, item] = ItemType(descr, context);
  if (kind == 'U') throw InputError(context + ": strings where numbers were expected");
  std::vector<double> values(data.size() / item);
  for (size_t i = 0; i < values.size(); ++i) {
    if (kind == 'f') {
      values[i] = item == 8 ? LoadAt<double>(data, i) : LoadAt<float>(data, i);
    } else if (kind == 'b' || kind == 'u') {
      values[i] = static_cast<double>(item == 1   ? LoadAt<uint8_t>(data, i)
                                      : item == 2 ? LoadAt<uint16_t>(data, i)
                                      : item == 4 ? LoadAt<uint32_t>(data, i)
                                                  : LoadAt<uint64_t>(data, i));
    } else {
      values[i] = static_cast<double>(item == 1   ? LoadAt<int8_t>(data, i)
                                      : item == 2 ? LoadAt<int16_t>(data, i)
                                      : item == 4 ? LoadAt<int32_t>(data, i)
                                                  : LoadAt<int64_t>(data, i));
    }
  }
  return values;
}

std::vector<int64_t> NpyArray::Integers(const std::string& context) const {
  const char kind = ItemType(descr, context).first;
  if (kind == 'f' || kind == 'U')
    throw InputError(context + ": type '" + descr + "' where integers were expected");
  if (descr == "<u8") throw InputError(context + ": unsigned 64-bit integers are not read");
  std::vector<int64_t> values;
  for (const double value : Doubles(context)) values.push_back(static_cast<int64_t>(value));
  return values;
}

std::vector<std::string> NpyArray::Strings(const std::string& context) const {
  const auto [kind, item] = ItemType(descr, context);
  if (kind != 'U') throw InputError(context + ": type '" + descr + "' where strings were expected");
  std::vector<std::string> strings;
  for (size_t at = 0; at < data.size(); at += item) {
    std::string text;
    for (size_t k = 0; k < item; k += 4) {
      const uint32_t unit = LoadAt<uint32_t>(data, (at + k) / 4);
      if (unit == 0) break;
      if (unit > 0x10ffff || (unit >= 0xd800 && unit <= 0xdfff))
        throw InputError(context + ": not a Unicode string");
      // UTF-8.
      if (unit < 0x80) {
        text += static_cast<char>(unit);
      } else if (unit < 0x800) {
        text += static_cast<char>(0xc0 | (unit >> 6));
        text += static_cast<char>(0x80 | (unit & 0x3f));
      } else if (unit < 0x10000) {
        text += static_cast<char>(0xe0 | (unit >> 12));
        text += static_cast<char>(0x80 | ((unit >> 6) & 0x3f));
        text += static_cast<char>(0x80 | (unit & 0x3f));
      } else {
        text += static_cast<char>(0xf0 | (unit >> 18));
        text += static_cast<char>(0x80 | ((unit >> 12) & 0x3f));
        text += static_cast<char>(0x80 | ((unit >> 6) & 0x3f));
        text += static_cast<char>(0x80 | (unit & 0x3f));
      }
    }
    strings.push_back(text);
  }
  return strings;
}

bool NpyArray::IsNone() const {
  return shape.empty() && !descr.empty() && descr[1] == 'U' &&
         data.find_first_not_of('\0') == std::string::npos;
}

std::map<std::string, NpyArray> ReadNpz(const std::string& bytes, const std::string& context) {
  zip_error_t error;
  zip_error_init(&error);
  zip_source_t* source = zip_source_buffer_create(bytes.data(), bytes.size(), 0, &error);
  if (!source) {
    zip_error_fini(&error);
    throw InputError(context + ": cannot read the archive");
  }
  std::unique_ptr<zip_t, ZipCloser> archive(
      zip_open_from_source(source, ZIP_RDONLY | ZIP_CHECKCONS, &error));
  if (!archive) {
    const std::string message = zip_error_strerror(&error);
    zip_source_free(source);
    zip_error_fini(&error);
    throw InputError(context + ": not a zip (.npz) archive: " + message);
  }
  zip_error_fini(&error);
  const zip_int64_t num_entries = zip_get_num_entries(archive.get(), 0);
  if (num_entries < 0 || num_entries > kMaxArrays) {
    throw InputError(context + ": " + std::to_string(num_entries) + " arrays (at most " +
                     std::to_string(kMaxArrays) + ")");
  }
  std::map<std::string, NpyArray> arrays;
  uint64_t budget = kMaxInflatedBytes;
  for (zip_int64_t i = 0; i < num_entries; ++i) {
    const char* raw_name = zip_get_name(archive.get(), static_cast<zip_uint64_t>(i), 0);
    std::string name = raw_name ? raw_name : "";
    if (name.size() < 5 || name.compare(name.size() - 4, 4, ".npy") != 0) {
      throw InputError(context + ": entry '" + name + "' is not an .npy array");
    }
    name.resize(name.size() - 4);
    const std::string npy =
        ReadEntry(archive.get(), static_cast<zip_uint64_t>(i), &budget, context);
    if (!arrays.emplace(name, ParseNpy(npy, context + ": '" + name + "'")).second) {
      throw InputError(context + ": two arrays named '" + name + "'");
    }
  }
  return arrays;
}

std::string DecodeBase85(const std::string& text, const std::string& context) {
  static const std::array<int, 256> kValue = [] {
    std::array<int, 256> value;
    value.fill(-1);
    const char alphabet[] =
        "0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz!#$%&()*+-;<=>?@^_`{|}~";
    for (int i = 0; i < 85; ++i) value[static_cast<unsigned char>(alphabet[i])] = i;
    return value;
  }();
  // Python pads a short last group with '~' (84) and cuts as many bytes.
  const size_t padding = (5 - text.size() % 5) % 5;
  const std::string padded = text + std::string(padding, '~');
  std::string out;
  out.reserve(padded.size() / 5 * 4);
  for (size_t i = 0; i < padded.size(); i += 5) {
    uint64_t word = 0;
    for (size_t k = 0; k < 5; ++k) {
      const int value = kValue[static_cast<unsigned char>(padded[i + k])];
      if (value < 0) {
        throw InputError(context + ": byte " + std::to_string(i + k) +
                         " is not a base-85 character");
      }
      word = word * 85 + static_cast<uint64_t>(value);
    }
    if (word > 0xffffffffu)
      throw InputError(context + ": base-85 group at byte " + std::to_string(i) + " overflows");
    for (int k = 3; k >= 0; --k) out += static_cast<char>((word >> (8 * k)) & 0xff);
  }
  out.resize(out.size() - padding);
  return out;
}

}  // namespace portcal
