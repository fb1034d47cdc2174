// Named-matrix files (matrix_files.hpp). Each file is built in memory, then
// written to `path + ".tmp"` and renamed into place. Formats:
//  - NPY format 1.0 (numpy.lib.format, NEP 1): "\x93NUMPY", version 1.0, a
//    little-endian uint16 header length, then the header, a Python dict literal
//    padded with spaces and ended by '\n' to a multiple of 64 bytes, then the data.
//  - .npz: a zip of "<key>.npy" entries, stored (method 0), as PKWARE's
//    APPNOTE.TXT 4.3.7 (local file header), 4.3.12 (central directory header)
//    and 4.3.16 (end of central directory record); no Zip64 (files under 4 GiB).
//  - MathWorks "MAT-File Format" (Level 5): a 128-byte header (text, subsystem
//    offset, version 0x0100, endian indicator "IM"), then one miMATRIX data
//    element per variable: array flags, dimensions, name, data; every element
//    an 8-byte tag (type, byte count) and data padded to 8 bytes.
#include "sim/matrix_files.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <stdexcept>

namespace kanegen {
namespace {

namespace fs = std::filesystem;

/// A little-endian byte buffer.
struct Bytes {
  std::string s;
  template <class T>
  void le(T v) {
    for (std::size_t i = 0; i < sizeof(T); ++i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
  }
  void u16(std::uint16_t v) { le(v); }
  void u32(std::uint32_t v) { le(v); }
  void f64(double d) {
    std::uint64_t b;
    std::memcpy(&b, &d, sizeof b);
    le(b);
  }
  void pad(std::size_t align) { s.resize((s.size() + align - 1) / align * align, '\0'); }
};

bool is_identifier(const std::string& k) {
  auto alpha = [](char c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || c == '_'; };
  if (k.empty() || !alpha(k[0])) return false;
  for (char c : k)
    if (!alpha(c) && !(c >= '0' && c <= '9')) return false;
  return true;
}

/// Keys are identifiers and distinct across matrices and name lists.
void check_keys(const NamedMatrices& m) {
  std::set<std::string> seen;
  auto check = [&](const std::string& k) {
    if (!is_identifier(k)) throw std::invalid_argument(fmt::format("matrix file key '{}' is not an identifier", k));
    if (!seen.insert(k).second) throw std::invalid_argument(fmt::format("matrix file key '{}' appears twice", k));
  };
  for (const auto& e : m.matrices) check(e.first);
  for (const auto& e : m.names) check(e.first);
}

/// The code points of a UTF-8 string (std::invalid_argument if it is not UTF-8).
std::u32string utf8_decode(const std::string& s) {
  auto bad = [&]() { return std::invalid_argument(fmt::format("name '{}' is not valid UTF-8", s)); };
  static constexpr char32_t least[] = {0, 0x80, 0x800, 0x10000};  // shortest form per length
  std::u32string out;
  for (std::size_t i = 0; i < s.size();) {
    const auto c = static_cast<unsigned char>(s[i]);
    const int n = c < 0x80 ? 0 : (c & 0xE0) == 0xC0 ? 1 : (c & 0xF0) == 0xE0 ? 2 : (c & 0xF8) == 0xF0 ? 3 : -1;
    if (n < 0 || i + n >= s.size()) throw bad();
    char32_t cp = n == 0 ? c : c & (0x3F >> n);
    for (int j = 1; j <= n; ++j) {
      const auto d = static_cast<unsigned char>(s[i + j]);
      if ((d & 0xC0) != 0x80) throw bad();
      cp = cp << 6 | (d & 0x3F);
    }
    if (cp < least[n] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) throw bad();
    out.push_back(cp);
    i += n + 1;
  }
  return out;
}

void write_atomically(const std::string& path, const std::string& bytes) {
  const std::string tmp = path + ".tmp";
  auto fail = [&](const std::string& why) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw std::runtime_error(fmt::format("cannot write {}: {}", path, why));
  };
  std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
  if (!f) fail(std::strerror(errno));
  f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  f.close();
  if (!f) fail(std::strerror(errno));
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) fail(ec.message());
}

// ---- NPY and zip ----

std::string npy(const std::string& descr, const std::string& shape, const std::string& data) {
  std::string header = fmt::format("{{'descr': '{}', 'fortran_order': False, 'shape': {}, }}", descr, shape);
  const std::size_t total = (10 + header.size() + 1 + 63) / 64 * 64;  // magic 6, version 2, length 2, '\n'
  header.append(total - 10 - header.size() - 1, ' ') += '\n';
  Bytes b;
  b.s.assign("\x93NUMPY\x01\x00", 8);
  b.u16(static_cast<std::uint16_t>(header.size()));
  return b.s + header + data;
}

std::string npy_matrix(const Eigen::MatrixXd& a) {
  Bytes d;
  for (Eigen::Index i = 0; i < a.rows(); ++i)  // C order
    for (Eigen::Index j = 0; j < a.cols(); ++j) d.f64(a(i, j));
  return npy("<f8", fmt::format("({}, {})", a.rows(), a.cols()), d.s);
}

std::string npy_names(const std::vector<std::string>& names) {
  std::vector<std::u32string> u;
  std::size_t width = 1;
  for (const auto& s : names) width = std::max(width, u.emplace_back(utf8_decode(s)).size());
  Bytes d;
  for (const auto& s : u)
    for (std::size_t i = 0; i < width; ++i) d.u32(i < s.size() ? s[i] : 0);
  return npy(fmt::format("<U{}", width), fmt::format("({},)", names.size()), d.s);
}

/// A zip archive of stored entries (name, data).
std::string zip_stored(const std::string& path, const std::vector<std::pair<std::string, std::string>>& entries) {
  constexpr std::uint16_t version = 20, dos_time = 0, dos_date = (1 << 5) | 1;  // 1980-01-01 00:00
  auto too_large = [&]() { return std::runtime_error(fmt::format("cannot write {}: too large for a zip without Zip64", path)); };
  if (entries.size() > 0xFFFF) throw too_large();
  Bytes out, central;
  for (const auto& [name, data] : entries) {
    if (out.s.size() + data.size() + 1024 > std::numeric_limits<std::uint32_t>::max()) throw too_large();
    const auto size = static_cast<std::uint32_t>(data.size()), offset = static_cast<std::uint32_t>(out.s.size());
    const auto crc = static_cast<std::uint32_t>(crc32(0L, reinterpret_cast<const Bytef*>(data.data()), size));
    // Version needed, flags, method (stored), time, date, CRC-32, sizes, name length, extra length.
    auto common = [&](Bytes& b) {
      for (std::uint16_t v : {version, std::uint16_t{0}, std::uint16_t{0}, dos_time, dos_date}) b.u16(v);
      for (std::uint32_t v : {crc, size, size}) b.u32(v);
      b.u16(static_cast<std::uint16_t>(name.size()));
      b.u16(0);
    };
    out.u32(0x04034b50);
    common(out);
    out.s += name + data;
    central.u32(0x02014b50);
    central.u16(version);  // made by
    common(central);
    for (int i = 0; i < 3; ++i) central.u16(0);  // comment length, disk number, internal attributes
    central.u32(0);                              // external attributes
    central.u32(offset);
    central.s += name;
  }
  const auto cd_offset = static_cast<std::uint32_t>(out.s.size()), cd_size = static_cast<std::uint32_t>(central.s.size());
  out.s += central.s;
  out.u32(0x06054b50);
  out.u16(0);  // this disk
  out.u16(0);  // disk of the central directory
  out.u16(static_cast<std::uint16_t>(entries.size()));
  out.u16(static_cast<std::uint16_t>(entries.size()));
  out.u32(cd_size);
  out.u32(cd_offset);
  out.u16(0);  // comment length
  return out.s;
}

// ---- MAT-file Level 5 ----

enum : std::uint32_t { miINT8 = 1, miINT32 = 5, miUINT32 = 6, miDOUBLE = 9, miMATRIX = 14, miUTF8 = 16 };
enum : std::uint32_t { mxCELL_CLASS = 1, mxCHAR_CLASS = 4, mxDOUBLE_CLASS = 6 };

void element(Bytes& b, std::uint32_t type, const std::string& data) {
  b.u32(type);
  b.u32(static_cast<std::uint32_t>(data.size()));
  b.s += data;
  b.pad(8);
}

/// A miMATRIX element: array flags, dimensions rows x cols, name, then `body` (the data elements).
std::string mat_array(std::uint32_t cls, std::size_t rows, std::size_t cols, const std::string& name,
                      const std::string& body) {
  if (rows > INT32_MAX || cols > INT32_MAX) throw std::invalid_argument("MAT-file array larger than 2^31 - 1");
  Bytes flags, dims, content, out;
  flags.u32(cls);  // class in the low byte, no complex/global/logical flags
  flags.u32(0);
  dims.u32(static_cast<std::uint32_t>(rows));
  dims.u32(static_cast<std::uint32_t>(cols));
  element(content, miUINT32, flags.s);
  element(content, miINT32, dims.s);
  element(content, miINT8, name);
  content.s += body;
  element(out, miMATRIX, content.s);
  return out.s;
}

std::string mat_double(const std::string& name, const Eigen::MatrixXd& a) {
  Bytes data, body;
  for (Eigen::Index k = 0; k < a.size(); ++k) data.f64(a.data()[k]);  // Eigen's storage is column-major
  element(body, miDOUBLE, data.s);
  return mat_array(mxDOUBLE_CLASS, a.rows(), a.cols(), name, body.s);
}

std::string mat_cellstr(const std::string& name, const std::vector<std::string>& names) {
  std::string cells;
  for (const auto& s : names) {  // UTF-8 data, the length in characters (as scipy.io.savemat writes them)
    Bytes body;
    element(body, miUTF8, s);
    cells += mat_array(mxCHAR_CLASS, 1, utf8_decode(s).size(), "", body.s);
  }
  return mat_array(mxCELL_CLASS, names.size(), 1, name, cells);
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) {
    if (c == '"') q += '"';
    q += c;
  }
  return q + '"';
}

}  // namespace

void write_npz(const std::string& path, const NamedMatrices& m) {
  check_keys(m);
  std::vector<std::pair<std::string, std::string>> entries;
  for (const auto& [k, a] : m.matrices) entries.emplace_back(k + ".npy", npy_matrix(a));
  for (const auto& [k, n] : m.names) entries.emplace_back(k + ".npy", npy_names(n));
  write_atomically(path, zip_stored(path, entries));
}

void write_mat(const std::string& path, const NamedMatrices& m) {
  check_keys(m);
  auto matlab_name = [](const std::string& k) {  // MATLAB: a letter first, at most namelengthmax = 63
    if (k[0] == '_' || k.size() > 63) throw std::invalid_argument(fmt::format("'{}' is not a MATLAB variable name", k));
  };
  for (const auto& e : m.matrices) matlab_name(e.first);
  for (const auto& e : m.names) matlab_name(e.first);
  std::string text = "MATLAB 5.0 MAT-file, Platform: kanegen, Created by: kanegen write_mat";
  text.resize(116, ' ');
  Bytes b;
  b.s = text + std::string(8, '\0');  // no subsystem data
  b.u16(0x0100);
  b.s += "IM";  // 'M' << 8 | 'I' written little-endian
  for (const auto& [k, a] : m.matrices) b.s += mat_double(k, a);
  for (const auto& [k, n] : m.names) b.s += mat_cellstr(k, n);
  write_atomically(path, b.s);
}

std::vector<std::string> write_csv(const std::string& prefix, const NamedMatrices& m,
                                   const std::map<std::string, std::pair<std::string, std::string>>& labels) {
  check_keys(m);
  auto name_list = [&](const std::string& key) -> const std::vector<std::string>& {
    for (const auto& [k, n] : m.names)
      if (k == key) return n;
    throw std::invalid_argument(fmt::format("no name list '{}' for CSV labels", key));
  };
  for (const auto& [k, rc] : labels) {
    const auto it = std::find_if(m.matrices.begin(), m.matrices.end(), [&](const auto& e) { return e.first == k; });
    if (it == m.matrices.end()) throw std::invalid_argument(fmt::format("CSV labels for unknown matrix '{}'", k));
    if (name_list(rc.first).size() != std::size_t(it->second.rows()) ||
        name_list(rc.second).size() != std::size_t(it->second.cols()))
      throw std::invalid_argument(fmt::format("CSV labels '{}' x '{}' do not match the {} x {} matrix '{}'",
                                              rc.first, rc.second, it->second.rows(), it->second.cols(), k));
  }
  std::vector<std::string> paths;
  for (const auto& [k, a] : m.matrices) {
    const auto lab = labels.find(k);
    const std::vector<std::string>* rows = lab == labels.end() ? nullptr : &name_list(lab->second.first);
    std::string text;
    auto line = [&](std::vector<std::string> cells) {  // a lone empty cell quoted: not a blank line
      text += cells.size() == 1 && cells[0].empty() ? "\"\"" : fmt::format("{}", fmt::join(cells, ","));
      text += '\n';
    };
    if (rows) {
      std::vector<std::string> header{""};
      for (const auto& c : name_list(lab->second.second)) header.push_back(csv_field(c));
      line(header);
    }
    for (Eigen::Index i = 0; i < a.rows(); ++i) {
      std::vector<std::string> cells;
      if (rows) cells.push_back(csv_field((*rows)[i]));
      for (Eigen::Index j = 0; j < a.cols(); ++j) cells.push_back(fmt::format("{:.17g}", a(i, j)));
      line(cells);
    }
    paths.push_back(prefix + "_" + k + ".csv");
    write_atomically(paths.back(), text);
  }
  return paths;
}

}  // namespace kanegen
