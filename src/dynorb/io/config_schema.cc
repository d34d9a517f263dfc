#include "dynorb/io/config_schema.h"

#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <variant>

#include "dynorb/core/error.h"
#include "dynorb/io/atomic_file.h"

namespace dynorb {
namespace {

bool IsValidKey(const std::string& key, bool allow_dots) {
  if (key.empty() || !(std::isalpha(static_cast<unsigned char>(key[0])) || key[0] == '_')) return false;
  for (char c : key) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || (allow_dots && c == '.'))) {
      return false;
    }
  }
  return true;
}

// Makes OpenCV-FileStorage YAML (ORB-SLAM2 settings) acceptable to yaml-cpp without changing line
// numbers: comments out a "%YAML:1.0" directive and inserts the missing space in top-level
// "Key:value" lines (e.g. ORB-SLAM2's "Viewer.PointSize:2").
std::string NormalizeOpenCvYaml(const std::string& text) {
  std::istringstream in(text);
  std::string out, line;
  while (std::getline(in, line)) {
    if (line.rfind("%YAML:", 0) == 0) {
      line = "# " + line;
    } else if (!line.empty() && (std::isalpha(static_cast<unsigned char>(line[0])) || line[0] == '_')) {
      size_t i = 0;
      while (i < line.size() && (std::isalnum(static_cast<unsigned char>(line[i])) || line[i] == '_' ||
                                 line[i] == '.')) {
        ++i;
      }
      if (i + 1 < line.size() && line[i] == ':' && !std::isspace(static_cast<unsigned char>(line[i + 1])) &&
          line[i + 1] != ':') {
        line.insert(i + 1, " ");
      }
    }
    out += line;
    out += '\n';
  }
  return out;
}

std::string FormatDouble(double v) {
  char buf[64];
  for (int precision = 6; precision <= 17; ++precision) {
    std::snprintf(buf, sizeof(buf), "%.*g", precision, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  std::string s = buf;
  if (std::isfinite(v) && s.find_first_of(".eE") == std::string::npos) s += ".0";
  return s;
}

std::string Quote(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\t': out += "\\t"; break;
      default: out += c;
    }
  }
  return out + "\"";
}

std::string OneLine(std::string s) {
  for (char& c : s) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return s;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// ConfigSection

ConfigSection& ConfigSection::AddField(const std::string& key, Type type, void* value,
                                       const std::string& help) {
  if (!IsValidKey(key, /*allow_dots=*/name_.empty())) {
    throw std::logic_error("ConfigSection '" + name_ + "': invalid key '" + key + "'");
  }
  if (Find(key) != nullptr) {
    throw std::logic_error("ConfigSection '" + name_ + "': key '" + key + "' declared twice");
  }
  if (value == nullptr) throw std::logic_error("ConfigSection: null binding for '" + key + "'");
  fields_.push_back({key, type, value, help});
  return *this;
}

ConfigSection& ConfigSection::Add(const std::string& key, double* value, const std::string& help) {
  return AddField(key, Type::kDouble, value, help);
}
ConfigSection& ConfigSection::Add(const std::string& key, int* value, const std::string& help) {
  return AddField(key, Type::kInt, value, help);
}
ConfigSection& ConfigSection::Add(const std::string& key, bool* value, const std::string& help) {
  return AddField(key, Type::kBool, value, help);
}
ConfigSection& ConfigSection::Add(const std::string& key, std::string* value, const std::string& help) {
  return AddField(key, Type::kString, value, help);
}
ConfigSection& ConfigSection::Add(const std::string& key, std::vector<double>* value,
                                  const std::string& help) {
  return AddField(key, Type::kDoubleList, value, help);
}
ConfigSection& ConfigSection::Add(const std::string& key, std::vector<std::string>* value,
                                  const std::string& help) {
  return AddField(key, Type::kStringList, value, help);
}

ConfigSection& ConfigSection::OnLoaded(std::function<void()> fn) {
  finalizers_->push_back(std::move(fn));
  return *this;
}

const ConfigSection::Field* ConfigSection::Find(const std::string& key) const {
  for (const Field& f : fields_) {
    if (f.key == key) return &f;
  }
  return nullptr;
}

// ---------------------------------------------------------------------------------------------
// ConfigSchema

struct ConfigSchema::Impl {
  using Value = std::variant<double, int, bool, std::string, std::vector<double>, std::vector<std::string>>;
  struct Pending {
    const ConfigSection::Field* field;
    std::string path;
    Value value;
  };

  std::vector<std::function<void()>> finalizers;
  std::deque<ConfigSection> sections;  // [0] is the root; deque keeps references stable
  std::vector<std::string> ignored_prefixes;
  std::set<std::string> set_paths;

  ConfigSection* FindSection(const std::string& name) {
    for (ConfigSection& s : sections) {
      if (s.name_ == name) return &s;
    }
    return nullptr;
  }

  static std::string Where(const std::string& source, const YAML::Node& node) {
    const YAML::Mark mark = node.Mark();
    if (mark.line >= 0) return source + ":" + std::to_string(mark.line + 1);
    return source;
  }

  static double ToDouble(const std::string& text, const std::string& where, const std::string& path) {
    errno = 0;
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE || !std::isfinite(v)) {
      throw InputError(where + ": '" + path + "' expects a number, got '" + text + "'");
    }
    return v;
  }

  static Value Parse(const ConfigSection::Field& field, const YAML::Node& node, const std::string& where,
                     const std::string& path) {
    using Type = ConfigSection::Type;
    const bool is_list = field.type == Type::kDoubleList || field.type == Type::kStringList;
    if (is_list) {
      if (!node.IsSequence() && !node.IsNull()) {
        throw InputError(where + ": '" + path + "' expects a list, e.g. [a, b]");
      }
      std::vector<double> doubles;
      std::vector<std::string> strings;
      if (node.IsSequence()) {
        for (const YAML::Node& item : node) {
          if (!item.IsScalar()) throw InputError(where + ": '" + path + "' expects a list of scalars");
          if (field.type == Type::kDoubleList) {
            doubles.push_back(ToDouble(item.Scalar(), where, path));
          } else {
            strings.push_back(item.Scalar());
          }
        }
      }
      if (field.type == Type::kDoubleList) return doubles;
      return strings;
    }
    if (!node.IsScalar()) {
      throw InputError(where + ": '" + path + "' expects a single value" +
                       (node.IsNull() ? " but has none" : ""));
    }
    const std::string text = node.Scalar();
    switch (field.type) {
      case Type::kDouble:
        return ToDouble(text, where, path);
      case Type::kInt: {
        const double v = ToDouble(text, where, path);
        if (v != std::floor(v) || v < INT_MIN || v > INT_MAX) {
          throw InputError(where + ": '" + path + "' expects an integer, got '" + text + "'");
        }
        return static_cast<int>(v);
      }
      case Type::kBool: {
        std::string lower;
        for (char c : text) lower += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        if (lower == "true" || lower == "1") return true;
        if (lower == "false" || lower == "0") return false;
        throw InputError(where + ": '" + path + "' expects true/false (or 1/0), got '" + text + "'");
      }
      default:
        return text;
    }
  }

  static void Assign(const ConfigSection::Field& field, const Value& value) {
    using Type = ConfigSection::Type;
    switch (field.type) {
      case Type::kDouble: *static_cast<double*>(field.value) = std::get<double>(value); break;
      case Type::kInt: *static_cast<int*>(field.value) = std::get<int>(value); break;
      case Type::kBool: *static_cast<bool*>(field.value) = std::get<bool>(value); break;
      case Type::kString: *static_cast<std::string*>(field.value) = std::get<std::string>(value); break;
      case Type::kDoubleList:
        *static_cast<std::vector<double>*>(field.value) = std::get<std::vector<double>>(value);
        break;
      case Type::kStringList:
        *static_cast<std::vector<std::string>*>(field.value) = std::get<std::vector<std::string>>(value);
        break;
    }
  }

  static std::string Format(const ConfigSection::Field& field) {
    using Type = ConfigSection::Type;
    switch (field.type) {
      case Type::kDouble: return FormatDouble(*static_cast<const double*>(field.value));
      case Type::kInt: return std::to_string(*static_cast<const int*>(field.value));
      case Type::kBool: return *static_cast<const bool*>(field.value) ? "true" : "false";
      case Type::kString: return Quote(*static_cast<const std::string*>(field.value));
      case Type::kDoubleList: {
        std::string s = "[";
        for (double v : *static_cast<const std::vector<double>*>(field.value)) {
          s += (s.size() > 1 ? ", " : "") + FormatDouble(v);
        }
        return s + "]";
      }
      case Type::kStringList: {
        std::string s = "[";
        for (const std::string& v : *static_cast<const std::vector<std::string>*>(field.value)) {
          s += (s.size() > 1 ? ", " : "") + Quote(v);
        }
        return s + "]";
      }
    }
    return "";
  }

  void RunFinalizers(const std::string& source) {
    try {
      for (const auto& fn : finalizers) fn();
    } catch (const InputError& e) {
      throw InputError(source + ": " + e.what());
    }
  }

  void Commit(const std::vector<Pending>& pending) {
    for (const Pending& p : pending) {
      Assign(*p.field, p.value);
      set_paths.insert(p.path);
    }
  }

  void LoadDocument(const YAML::Node& doc, const std::string& source);
};

void ConfigSchema::Impl::LoadDocument(const YAML::Node& doc, const std::string& source) {
  if (doc.IsNull()) return;  // empty file: all defaults
  if (!doc.IsMap()) throw InputError(source + ": expected a mapping of 'key: value' at the top level");
  const ConfigSection& root = sections.front();
  std::vector<Pending> pending;
  std::set<std::string> seen;
  auto note_seen = [&](const std::string& path, const std::string& where) {
    if (!seen.insert(path).second) throw InputError(where + ": duplicate key '" + path + "'");
  };
  for (const auto& entry : doc) {
    const YAML::Node& key_node = entry.first;
    const std::string where = Where(source, key_node);
    if (!key_node.IsScalar()) throw InputError(where + ": keys must be plain names");
    const std::string key = key_node.Scalar();
    if (const ConfigSection::Field* field = root.Find(key)) {
      note_seen(key, where);
      pending.push_back({field, key, Parse(*field, entry.second, where, key)});
      continue;
    }
    if (ConfigSection* section = FindSection(key); section != nullptr && !key.empty()) {
      note_seen(key, where);
      if (entry.second.IsNull()) continue;
      if (!entry.second.IsMap()) {
        throw InputError(where + ": section '" + key + "' must be a mapping of 'key: value'");
      }
      for (const auto& item : entry.second) {
        const std::string item_where = Where(source, item.first);
        if (!item.first.IsScalar()) throw InputError(item_where + ": keys must be plain names");
        const std::string path = key + "." + item.first.Scalar();
        const ConfigSection::Field* field = section->Find(item.first.Scalar());
        if (field == nullptr) throw InputError(item_where + ": unknown key '" + path + "'");
        note_seen(path, item_where);
        pending.push_back({field, path, Parse(*field, item.second, item_where, path)});
      }
      continue;
    }
    bool ignored = false;
    for (const std::string& prefix : ignored_prefixes) ignored = ignored || key.rfind(prefix, 0) == 0;
    if (!ignored) throw InputError(where + ": unknown key '" + key + "'");
  }
  Commit(pending);
}

ConfigSchema::ConfigSchema() : impl_(std::make_unique<Impl>()) {
  impl_->sections.push_back(ConfigSection("", "", &impl_->finalizers));
}

ConfigSchema::~ConfigSchema() = default;

ConfigSection& ConfigSchema::Root() { return impl_->sections.front(); }

ConfigSection& ConfigSchema::Section(const std::string& name, const std::string& help) {
  if (ConfigSection* existing = impl_->FindSection(name); existing != nullptr && !name.empty()) {
    return *existing;
  }
  if (!IsValidKey(name, /*allow_dots=*/false)) {
    throw std::logic_error("ConfigSchema: invalid section name '" + name + "'");
  }
  if (Root().Find(name) != nullptr) {
    throw std::logic_error("ConfigSchema: section '" + name + "' collides with a root key");
  }
  impl_->sections.push_back(ConfigSection(name, help, &impl_->finalizers));
  return impl_->sections.back();
}

void ConfigSchema::IgnorePrefix(const std::string& prefix) { impl_->ignored_prefixes.push_back(prefix); }

namespace {

std::string ReadConfigFile(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError("config file not found: " + path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot open config file " + path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

void ConfigSchema::LoadString(const std::string& yaml_text, const std::string& source_name) {
  ParseAndAssign(yaml_text, source_name);
  impl_->RunFinalizers(source_name);
}

void ConfigSchema::Load(const std::string& path) { LoadString(ReadConfigFile(path), path); }

void ConfigSchema::LoadFiles(const std::vector<std::string>& paths) {
  std::string sources;
  for (const std::string& path : paths) {
    ParseAndAssign(ReadConfigFile(path), path);
    sources += (sources.empty() ? "" : " + ") + path;
  }
  impl_->RunFinalizers(sources);
}

void ConfigSchema::ParseAndAssign(const std::string& yaml_text, const std::string& source_name) {
  YAML::Node doc;
  try {
    doc = YAML::Load(NormalizeOpenCvYaml(yaml_text));
  } catch (const YAML::Exception& e) {
    const std::string where =
        e.mark.line >= 0 ? source_name + ":" + std::to_string(e.mark.line + 1) : source_name;
    throw InputError(where + ": invalid YAML: " + e.msg);
  }
  try {
    impl_->LoadDocument(doc, source_name);
  } catch (const YAML::Exception& e) {
    throw InputError(source_name + ": invalid YAML: " + e.msg);
  }
}

void ConfigSchema::Override(const std::string& path, const std::string& value_text) {
  const std::string source = "override '" + path + "=" + value_text + "'";
  const ConfigSection::Field* field = Root().Find(path);
  if (field == nullptr) {
    const size_t dot = path.find('.');
    ConfigSection* section = dot == std::string::npos ? nullptr : impl_->FindSection(path.substr(0, dot));
    if (section != nullptr && !section->name().empty()) field = section->Find(path.substr(dot + 1));
  }
  if (field == nullptr) throw InputError(source + ": unknown key '" + path + "'");
  YAML::Node node;
  try {
    node = YAML::Load(value_text);
  } catch (const YAML::Exception& e) {
    throw InputError(source + ": invalid value: " + e.msg);
  }
  impl_->Commit({{field, path, Impl::Parse(*field, node, source, path)}});
  impl_->RunFinalizers(source);
}

bool ConfigSchema::IsSet(const std::string& path) const { return impl_->set_paths.count(path) > 0; }

std::string ConfigSchema::ToYaml() const {
  std::ostringstream out;
  out << "# dynorb configuration (effective values). Loads back with the same schema.\n";
  for (const ConfigSection& section : impl_->sections) {
    const bool root = section.name().empty();
    if (!root) {
      out << "\n" << section.name() << ":";
      if (!section.help_.empty()) out << "  # " << OneLine(section.help_);
      out << "\n";
      if (section.fields_.empty()) out << "  {}\n";  // unreachable in practice; keeps YAML valid
    }
    for (const ConfigSection::Field& field : section.fields_) {
      out << (root ? "" : "  ") << field.key << ": " << Impl::Format(field);
      if (!field.help.empty()) out << "  # " << OneLine(field.help);
      out << "\n";
    }
  }
  return out.str();
}

void ConfigSchema::Write(const std::string& path) const { WriteFileAtomically(path, ToYaml()); }

}  // namespace dynorb
