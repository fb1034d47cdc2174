#include "engine/jit_cache.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <signal.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "model/model_hash.hpp"

namespace kanegen::jit_cache {

namespace fs = std::filesystem;

namespace {

std::string read_all(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) return {};
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

constexpr const char* kTempPrefix = ".tmp-";

}  // namespace

std::string record_path(const std::string& so_path) {
  fs::path p(so_path);
  p.replace_extension(".json");
  return p.string();
}

std::string file_stem(const std::string& name) {
  std::string r;
  for (char c : name) {
    if (r.size() >= 32) break;
    r += (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-') ? c : '_';
  }
  return r.empty() ? std::string("model") : r;
}

std::optional<LibraryRecord> verified_record(const std::string& so_path,
                                             const std::function<bool(const LibraryRecord&)>& wanted) {
  std::error_code ec;
  const auto size = fs::file_size(so_path, ec);
  if (ec) return std::nullopt;
  const std::string text = read_all(record_path(so_path));
  if (text.empty()) return std::nullopt;
  LibraryRecord r;
  try {
    const auto j = nlohmann::json::parse(text);
    r.api_symbol = j.at("api_symbol").get<std::string>();
    r.size = j.at("size").get<long long>();
    r.checksum = j.at("fnv1a64").get<std::string>();
    r.jacobian_for_integration = j.value("jacobian_for_integration", true);
    r.udot_form = j.value("udot_form", "");
    r.compiler = j.value("compiler", "");
    r.preferred = j.value("preferred", false);
    r.udot_ns = j.value("udot_ns", 0.0);
    r.main_udot_ns = j.value("main_udot_ns", 0.0);
    r.main_checksum = j.value("main_fnv1a64", "");
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;
  }
  if (r.size != static_cast<long long>(size) || (wanted && !wanted(r))) return std::nullopt;
  if (fnv1a64_hex(read_all(so_path)) != r.checksum) return std::nullopt;
  return r;
}

LibraryRecord make_record(const std::string& library_file, const std::string& api_symbol) {
  const std::string bytes = read_all(library_file);
  if (bytes.empty()) throw std::runtime_error(fmt::format("kanegen: cannot read the compiled library {}", library_file));
  LibraryRecord r;
  r.api_symbol = api_symbol;
  r.size = static_cast<long long>(bytes.size());
  r.checksum = fnv1a64_hex(bytes);
  return r;
}

void write_record(const std::string& so_path, const LibraryRecord& r) {
  const std::string path = record_path(so_path);
  const std::string tmp = fmt::format("{}.{}.tmp", path, getpid());
  nlohmann::ordered_json j;
  j["api_symbol"] = r.api_symbol;
  j["size"] = r.size;
  j["fnv1a64"] = r.checksum;
  j["jacobian_for_integration"] = r.jacobian_for_integration;
  j["udot_form"] = r.udot_form;
  if (!r.compiler.empty()) {
    j["compiler"] = r.compiler;
    j["preferred"] = r.preferred;
    j["udot_ns"] = r.udot_ns;
    j["main_udot_ns"] = r.main_udot_ns;
    j["main_fnv1a64"] = r.main_checksum;
  }
  {
    std::ofstream out(tmp, std::ios::binary);
    out << j.dump() << "\n";
    out.close();
    if (!out) {
      std::error_code ec;
      fs::remove(tmp, ec);
      throw std::runtime_error(fmt::format("kanegen: cannot write {}", tmp));
    }
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw std::runtime_error(fmt::format("kanegen: cannot write {}: {}", path, ec.message()));
  }
}

void remove_stale_temps(const std::string& dir) {
  std::error_code ec;
  const auto now = fs::file_time_type::clock::now();
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.rfind(kTempPrefix, 0) != 0) continue;
    // .tmp-<pid>-XXXXXX: removable when that process is gone, or after a day.
    const long pid = std::strtol(name.c_str() + std::strlen(kTempPrefix), nullptr, 10);
    const bool dead = pid > 0 && kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH;
    std::error_code ec2;
    const auto t = fs::last_write_time(it->path(), ec2);
    const bool old = !ec2 && now - t > std::chrono::hours(24);
    if (dead || old) fs::remove_all(it->path(), ec2);
  }
}

std::string make_temp_dir(const std::string& dir) {
  std::string tmpl = (fs::path(dir) / fmt::format("{}{}-XXXXXX", kTempPrefix, getpid())).string();
  if (!mkdtemp(tmpl.data()))
    throw std::runtime_error(
        fmt::format("kanegen: cannot create a temporary directory in {}: {}", dir, std::strerror(errno)));
  return tmpl;
}

}  // namespace kanegen::jit_cache
