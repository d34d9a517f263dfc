#include "dynorb/io/config_schema.h"

#include <yaml-cpp/yaml.h>

#include <cctype>
#include <deque>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include "dynorb/core/error.h"
#include "dynorb/io/atomic_file.h"
#include "dynorb/io/config_value.h"

namespace dynorb {
namespace {

bool IsValidKey(const std::string& key, bool allow_dots) {
  if (key.empty() || !(std::isalpha(static_cast<unsigned char>(key[0])) || key[0] == '_'))
    return false;
  for (char c : key) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || (allow_dots && c == '.'))) {
      return false;
    }
  }
  return true;
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
ConfigSection& ConfigSection::Add(const std::string& key, std::string* value,
                                  const std::string& help) {
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
  struct Pending {
    const ConfigSection::Field* field;
    std::string path;
    config_internal::Value value;
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

  void RunFinalizers(const std::string& source) {
    try {
      for (const auto& fn : finalizers) fn();
    } catch (const InputError& e) {
      throw InputError(source + ": " + e.what());
    }
  }

  void Commit(const std::vector<Pending>& pending) {
    for (const Pending& p : pending) {
      config_internal::AssignValue(p.field->type, p.field->value, p.value);
      set_paths.insert(p.path);
    }
  }

  void LoadDocument(const YAML::Node& doc, const std::string& source);
};

void ConfigSchema::Impl::LoadDocument(const YAML::Node& doc, const std::string& source) {
  if (doc.IsNull()) return;  // empty file: all defaults
  if (!doc.IsMap())
    throw InputError(source + ": expected a mapping of 'key: value' at the top level");
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
      pending.push_back(
          {field, key, config_internal::ParseValue(field->type, entry.second, where, key)});
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
        pending.push_back(
            {field, path, config_internal::ParseValue(field->type, item.second, item_where, path)});
      }
      continue;
    }
    bool ignored = false;
    for (const std::string& prefix : ignored_prefixes)
      ignored = ignored || key.rfind(prefix, 0) == 0;
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

void ConfigSchema::IgnorePrefix(const std::string& prefix) {
  impl_->ignored_prefixes.push_back(prefix);
}

namespace {

std::string ReadConfigFile(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw InputError("config file not found: " + path);
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
    doc = YAML::Load(config_internal::NormalizeOpenCvYaml(yaml_text));
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
    ConfigSection* section =
        dot == std::string::npos ? nullptr : impl_->FindSection(path.substr(0, dot));
    if (section != nullptr && !section->name().empty()) field = section->Find(path.substr(dot + 1));
  }
  if (field == nullptr) throw InputError(source + ": unknown key '" + path + "'");
  YAML::Node node;
  try {
    node = YAML::Load(value_text);
  } catch (const YAML::Exception& e) {
    throw InputError(source + ": invalid value: " + e.msg);
  }
  impl_->Commit({{field, path, config_internal::ParseValue(field->type, node, source, path)}});
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
      if (!section.help_.empty()) out << "  # " << config_internal::OneLine(section.help_);
      out << "\n";
      if (section.fields_.empty()) out << "  {}\n";  // unreachable in practice; keeps YAML valid
    }
    for (const ConfigSection::Field& field : section.fields_) {
      out << (root ? "" : "  ") << field.key << ": "
          << config_internal::FormatValue(field.type, field.value);
      if (!field.help.empty()) out << "  # " << config_internal::OneLine(field.help);
      out << "\n";
    }
  }
  return out.str();
}

void ConfigSchema::Write(const std::string& path) const { WriteFileAtomically(path, ToYaml()); }

}  // namespace dynorb
