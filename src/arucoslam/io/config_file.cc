#include "arucoslam/io/config_file.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <functional>
#include <iterator>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <vector>

#include "arucoslam/pipeline/options_visit.h"
#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"

namespace arucoslam {
namespace {

template <class T>
struct IsOptional : std::false_type {};
template <class T>
struct IsOptional<std::optional<T>> : std::true_type {};

// The keys of an options struct, in order.
struct KeyCollector {
  std::vector<std::string_view> keys;
  template <class T>
  void operator()(std::string_view key, T&, std::string_view) {
    keys.push_back(key);
  }
};

// An options struct with a VisitOptions is a section; anything else visited is a scalar.
template <class T>
constexpr bool kIsSection = requires(T& value, KeyCollector& keys) {
  VisitOptions(value, keys);
};

std::string KeyPath(const std::string& section, std::string_view key) {
  return section.empty() ? std::string(key) : fmt::format("{}.{}", section, key);
}

// ---- Scalars: bool, integers, double and named enums, written so that they read back equal.

template <class T>
std::string FormatScalar(const T& value) {
  if constexpr (std::is_same_v<T, bool>) {
    return value ? "true" : "false";
  } else if constexpr (std::is_enum_v<T>) {
    for (const auto& [each, name] : EnumNames(value)) {
      if (each == value) return std::string(name);
    }
    throw std::logic_error("an enum value without a name in EnumNames");
  } else if constexpr (std::is_integral_v<T>) {
    return std::to_string(value);
  } else {
    static_assert(std::is_same_v<T, double>, "options fields: bool, int, uint32, double, enum");
    char buffer[32];
    const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);  // shortest exact
    std::string text(buffer, result.ptr);
    if (text.find_first_of(".en") == std::string::npos) text += ".0";  // reads as a number
    return text;
  }
}

template <class T>
std::optional<T> ParseScalar(std::string_view text) {
  if constexpr (std::is_same_v<T, bool>) {  // YAML 1.2's core schema
    if (text == "true" || text == "True" || text == "TRUE") return true;
    if (text == "false" || text == "False" || text == "FALSE") return false;
    return std::nullopt;
  } else if constexpr (std::is_enum_v<T>) {
    for (const auto& [each, name] : EnumNames(T{})) {
      if (name == text) return each;
    }
    return std::nullopt;
  } else {
    if (!text.empty() && text.front() == '+') text.remove_prefix(1);
    T value{};
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (error != std::errc() || end != text.data() + text.size()) return std::nullopt;
    if constexpr (std::is_floating_point_v<T>) {
      if (!std::isfinite(value)) return std::nullopt;
    }
    return value;
  }
}

template <class T>
std::string ExpectedScalar() {
  if constexpr (std::is_same_v<T, bool>) {
    return "true or false";
  } else if constexpr (std::is_enum_v<T>) {
    std::string names;
    for (const auto& [each, name] : EnumNames(T{})) {
      fmt::format_to(std::back_inserter(names), "{}{}", names.empty() ? "" : ", ", name);
    }
    return "one of " + names;
  } else if constexpr (std::is_signed_v<T>) {
    return std::is_integral_v<T> ? "an integer" : "a number";
  } else {
    return fmt::format("an integer from 0 to {}", std::numeric_limits<T>::max());
  }
}

// ---- Writer

// Writes each visited field as one line `key: value  # comment`, sections indented below
// their key. Inside an unset optional section the lines are commented out.
class YamlWriter {
 public:
  template <class T>
  void operator()(std::string_view key, T& value, std::string_view comment) {
    if constexpr (IsOptional<T>::value) {
      if (value) {
        Section(key, *value, comment);
        return;
      }
      Line(key, "null",
           fmt::format("{}; unset: to set it, replace null by the keys below", comment));
      typename T::value_type defaults;
      ++depth_;
      ++commented_;
      VisitOptions(defaults, *this);
      --commented_;
      --depth_;
    } else if constexpr (kIsSection<T>) {
      Section(key, value, comment);
    } else {
      if (depth_ == 0 && after_section_) text_ += '\n';
      after_section_ = false;
      Line(key, FormatScalar(value), comment);
    }
  }

  std::string& text() { return text_; }

 private:
  template <class Options>
  void Section(std::string_view key, Options& options, std::string_view comment) {
    if (depth_ == 0) text_ += '\n';
    Line(key, "", comment);
    ++depth_;
    VisitOptions(options, *this);
    --depth_;
    after_section_ = depth_ == 0;
  }

  void Line(std::string_view key, std::string_view value, std::string_view comment) {
    text_.append(2 * depth_, ' ');
    if (commented_ > 0) text_ += "# ";
    fmt::format_to(std::back_inserter(text_), "{}:{}{}  # {}\n", key, value.empty() ? "" : " ",
                   value, comment);
  }

  std::string text_;
  int depth_ = 0;
  int commented_ = 0;
  bool after_section_ = false;  // the last top-level entry was a section: a blank line follows
};

// ---- Reader

// What a node holds, for "found ..." in messages.
std::string Found(const YAML::Node& node) {
  if (node.IsScalar()) return fmt::format("found '{}'", node.Scalar());
  if (node.IsSequence()) return "found a list";
  if (node.IsMap()) return "found a section";
  return "found nothing";
}

std::size_t EditDistance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1] ? 1 : 0)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// One value the file set in a section, and how to put the section's previous value back
// (swap() exchanges the two; twice restores the file's).
struct Change {
  std::string key_path;
  YAML::Mark mark;
  std::string text;
  std::function<void()> swap;
};

class ConfigReader {
 public:
  explicit ConfigReader(std::string source) : source_(std::move(source)) {}

  // Reads the map `node` into `options` (section `path`, empty at the top), then checks them.
  template <class Options>
  void ReadSection(const YAML::Node& node, const std::string& path, Options& options);

  [[noreturn]] void Fail(const std::string& path, const YAML::Mark& mark,
                         const std::string& message) const {
    const std::string line = mark.line >= 0 ? fmt::format("line {}", mark.line + 1) : "";
    std::string where = path;
    if (!line.empty()) where = path.empty() ? line : fmt::format("{} ({})", path, line);
    throw InputError(source_, where.empty() ? message : fmt::format("{}: {}", where, message));
  }

 private:
  // The fields of one section found in its map.
  class SectionVisitor {
   public:
    using Entries = std::map<std::string, std::pair<YAML::Node, YAML::Node>>;  // key, value
    SectionVisitor(ConfigReader& reader, const std::string& path, const Entries& entries)
        : reader_(reader), path_(path), entries_(entries) {}

    template <class T>
    void operator()(std::string_view key, T& value, std::string_view) {
      const auto entry = entries_.find(std::string(key));
      if (entry == entries_.end()) return;
      const auto& [key_node, value_node] = entry->second;
      const std::string key_path = KeyPath(path_, key);
      if constexpr (IsOptional<T>::value) {
        if (!value_node.IsNull()) {
          if (!value) value.emplace();
          reader_.ReadSection(value_node, key_path, *value);
          return;
        }
        Set(key_path, key_node.Mark(), "null", value, T{});
      } else if constexpr (kIsSection<T>) {
        reader_.ReadSection(value_node, key_path, value);
      } else {
        const std::optional<T> parsed =
            value_node.IsScalar() ? ParseScalar<T>(value_node.Scalar()) : std::nullopt;
        if (!parsed) {
          reader_.Fail(key_path, key_node.Mark(),
                       fmt::format("expected {}, {}", ExpectedScalar<T>(), Found(value_node)));
        }
        Set(key_path, key_node.Mark(), value_node.Scalar(), value, *parsed);
      }
    }

    std::vector<Change>& changes() { return changes_; }

   private:
    template <class T>
    void Set(const std::string& key_path, const YAML::Mark& mark, const std::string& text, T& value,
             T new_value) {
      std::swap(value, new_value);
      changes_.push_back({key_path, mark, text, [&value, other = std::move(new_value)]() mutable {
                            std::swap(value, other);
                          }});
    }

    ConfigReader& reader_;
    const std::string& path_;
    const Entries& entries_;
    std::vector<Change> changes_;
  };

  // A section's Check() fails: names the value the file set that makes it fail, and the
  // reason the check gave (`why`, a field path relative to the section).
  [[noreturn]] void FailCheck(const std::string& path, const YAML::Node& node,
                              std::vector<Change>& changes, const std::string& why,
                              const std::function<bool()>& check) const;

  std::string source_;
};

template <class Options>
void ConfigReader::ReadSection(const YAML::Node& node, const std::string& path, Options& options) {
  if (!node.IsMap()) {
    Fail(path, node.Mark(),
         fmt::format("expected {}, {}",
                     path.empty() ? "a map of sections and keys (as run --print-config writes)"
                                  : "a section (keys indented below it)",
                     Found(node)));
  }
  KeyCollector known;
  VisitOptions(options, known);
  SectionVisitor::Entries entries;
  for (const auto& entry : node) {
    const std::string key = entry.first.IsScalar() ? entry.first.Scalar() : std::string();
    if (std::find(known.keys.begin(), known.keys.end(), key) == known.keys.end()) {
      std::string message = key.empty() ? "expected a key name" : "unknown key";
      for (const std::string_view candidate : known.keys) {
        if (EditDistance(key, candidate) <= 2) {
          message += fmt::format(" (did you mean {}?)", candidate);
          break;
        }
      }
      Fail(KeyPath(path, key), entry.first.Mark(), message);
    }
    if (!entries.emplace(key, std::pair(entry.first, entry.second)).second) {
      Fail(KeyPath(path, key), entry.first.Mark(), "duplicate key");
    }
  }
  SectionVisitor fields(*this, path, entries);
  VisitOptions(options, fields);
  if (std::string why; !options.Check(&why)) {
    FailCheck(path, node, fields.changes(), why, [&] { return options.Check(); });
  }
}

void ConfigReader::FailCheck(const std::string& path, const YAML::Node& node,
                             std::vector<Change>& changes, const std::string& why,
                             const std::function<bool()>& check) const {
  const std::string section = path.empty() ? "top-level" : path;
  const std::string reason = KeyPath(path, why);
  // The values whose previous value alone passes the check; else all the section's values.
  std::vector<const Change*> culprits;
  for (Change& change : changes) {
    change.swap();
    if (check()) culprits.push_back(&change);
    change.swap();
  }
  if (culprits.size() == 1) {
    Fail(culprits[0]->key_path, culprits[0]->mark,
         fmt::format("{} is out of range or inconsistent with the other {} options: {}",
                     culprits[0]->text, section, reason));
  }
  if (culprits.empty()) {
    for (const Change& change : changes) culprits.push_back(&change);
  }
  std::string values;
  for (const Change* change : culprits) {
    fmt::format_to(std::back_inserter(values), "{}{}: {} (line {})", values.empty() ? "" : ", ",
                   change->key_path, change->text, change->mark.line + 1);
  }
  const YAML::Mark mark = path.empty() ? YAML::Mark::null_mark() : node.Mark();
  Fail(path, mark,
       values.empty() ? fmt::format("the {} options fail their check: {}", section, reason)
                      : fmt::format("these values fail the {} options' check together: {}; {}",
                                    section, values, reason));
}

}  // namespace

std::string SystemOptionsYaml(const SystemOptions& options) {
  YamlWriter writer;
  writer.text() =
      "# arucoslam run options (`arucoslam run --print-config`): every option of the SLAM, one\n"
      "# section per options struct, units as the comments say (metres, radians, seconds,\n"
      "# pixels). `arucoslam run --config FILE` reads such a file: keys left out keep their\n"
      "# defaults; command-line flags (--blocking, --features, ...) override the file.\n"
      "# Not here: the marker map (the sequence's markers.json or --markers; it also names the\n"
      "# detector's dictionary) and the vocabulary (--vocabulary).\n";
  SystemOptions copy = options;
  VisitOptions(copy, writer);
  return std::move(writer.text());
}

void ParseSystemOptions(std::string_view text, const std::string& source, SystemOptions& options) {
  YAML::Node root;
  try {
    root = YAML::Load(std::string(text));
  } catch (const YAML::Exception& error) {
    throw InputError(source, fmt::format("not valid YAML: line {}, column {}: {}",
                                         error.mark.line + 1, error.mark.column + 1, error.msg));
  }
  if (root.IsNull()) return;  // empty, or only comments
  SystemOptions read = options;
  try {
    ConfigReader(source).ReadSection(root, "", read);
  } catch (const YAML::Exception& error) {
    throw InputError(source, fmt::format("unreadable YAML: {}", error.what()));
  }
  options = std::move(read);
}

void ReadSystemOptions(const std::filesystem::path& path, SystemOptions& options) {
  RequireFile(path, "config file");
  ParseSystemOptions(ReadTextFile(path), path.string(), options);
}

}  // namespace arucoslam
