// The vocabulary file (little-endian), version 1:
//   char[8]  magic "ASLAMBOW"
//   u32      version (1)
//   u32      branching k, u32 levels L, u32 number of training images, u32 number of nodes n
//   n-1 times (nodes 1..n-1, breadth-first; the root is implicit):
//            u32 parent, u8[32] centre descriptor, f64 weight (idf for leaves, 0 otherwise)
//   u64      FNV-1a hash of every byte before it
#include <bit>
#include <cmath>
#include <cstring>
#include <string>

#include "arucoslam/feature/vocabulary.h"
#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"

namespace arucoslam {
namespace {

static_assert(std::endian::native == std::endian::little, "vocabulary I/O assumes little-endian");

constexpr char kMagic[8] = {'A', 'S', 'L', 'A', 'M', 'B', 'O', 'W'};
constexpr std::uint32_t kVersion = 1;
constexpr std::size_t kHeaderBytes = 8 + 5 * 4;
constexpr std::size_t kNodeBytes = 4 + kOrbDescriptorBytes + 8;
constexpr std::size_t kHashBytes = 8;

std::uint64_t Fnv1a(const char* data, std::size_t size) {
  std::uint64_t hash = 14695981039346656037ull;
  for (std::size_t i = 0; i < size; ++i) {
    hash ^= static_cast<unsigned char>(data[i]);
    hash *= 1099511628211ull;
  }
  return hash;
}

template <typename T>
void Append(std::string& out, const T& value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof(T));
}

template <typename T>
T ReadAt(const std::string& bytes, std::size_t offset) {
  T value;
  std::memcpy(&value, bytes.data() + offset, sizeof(T));
  return value;
}

}  // namespace

std::string Vocabulary::ToBytes() const {
  std::string out;
  out.reserve(kHeaderBytes + nodes_.size() * kNodeBytes + kHashBytes);
  out.append(kMagic, sizeof(kMagic));
  Append(out, kVersion);
  Append(out, static_cast<std::uint32_t>(branching_));
  Append(out, static_cast<std::uint32_t>(levels_));
  Append(out, num_training_images_);
  Append(out, static_cast<std::uint32_t>(nodes_.size()));
  for (std::size_t i = 1; i < nodes_.size(); ++i) {
    Append(out, nodes_[i].parent);
    out.append(reinterpret_cast<const char*>(nodes_[i].descriptor.data()), kOrbDescriptorBytes);
    Append(out, nodes_[i].weight);
  }
  Append(out, Fnv1a(out.data(), out.size()));
  return out;
}

Vocabulary Vocabulary::FromBytes(const std::string& bytes, const std::string& source) {
  if (bytes.size() < sizeof(kMagic) || std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0) {
    throw InputError(source, "not an arucoslam vocabulary file (wrong magic)");
  }
  if (bytes.size() < kHeaderBytes) {
    throw InputError(source, "truncated vocabulary file: " + std::to_string(bytes.size()) +
                                 " bytes, the header alone needs " + std::to_string(kHeaderBytes));
  }
  const auto version = ReadAt<std::uint32_t>(bytes, 8);
  if (version != kVersion) {
    throw InputError(source, "vocabulary file version " + std::to_string(version) +
                                 ", this build reads version " + std::to_string(kVersion));
  }
  Vocabulary vocabulary;
  vocabulary.branching_ = static_cast<int>(ReadAt<std::uint32_t>(bytes, 12));
  vocabulary.levels_ = static_cast<int>(ReadAt<std::uint32_t>(bytes, 16));
  vocabulary.num_training_images_ = ReadAt<std::uint32_t>(bytes, 20);
  const auto num_nodes = ReadAt<std::uint32_t>(bytes, 24);
  const VocabularyOptions shape{vocabulary.branching_, vocabulary.levels_};
  if (!shape.Check() || num_nodes < 2) {
    throw InputError(source, "bad vocabulary header (k " + std::to_string(vocabulary.branching_) +
                                 ", L " + std::to_string(vocabulary.levels_) + ", nodes " +
                                 std::to_string(num_nodes) + ")");
  }
  const std::size_t expected = kHeaderBytes + (num_nodes - 1) * kNodeBytes + kHashBytes;
  if (bytes.size() != expected) {
    throw InputError(source, std::string(bytes.size() < expected ? "truncated" : "oversized") +
                                 " vocabulary file: " + std::to_string(bytes.size()) +
                                 " bytes, expected " + std::to_string(expected) + " for " +
                                 std::to_string(num_nodes) + " nodes");
  }
  if (Fnv1a(bytes.data(), expected - kHashBytes) != ReadAt<std::uint64_t>(bytes, expected - 8)) {
    throw InputError(source, "vocabulary file is corrupted (checksum mismatch)");
  }
  vocabulary.nodes_.resize(num_nodes);
  std::size_t offset = kHeaderBytes;
  for (std::uint32_t i = 1; i < num_nodes; ++i, offset += kNodeBytes) {
    Node& node = vocabulary.nodes_[i];
    node.parent = ReadAt<std::uint32_t>(bytes, offset);
    std::memcpy(node.descriptor.data(), bytes.data() + offset + 4, kOrbDescriptorBytes);
    node.weight = ReadAt<double>(bytes, offset + 4 + kOrbDescriptorBytes);
    if (!std::isfinite(node.weight) || node.weight < 0.0) {
      throw InputError(source, "node " + std::to_string(i) + ": weight must be finite and >= 0");
    }
  }
  vocabulary.LinkTree(source);
  return vocabulary;
}

void Vocabulary::LinkTree(const std::string& source) {
  words_.clear();
  for (Node& node : nodes_) {
    node.first_child = 0;
    node.num_children = 0;
    node.word = 0;
  }
  nodes_[0].parent = 0;
  nodes_[0].depth = 0;
  for (std::size_t i = 1; i < nodes_.size(); ++i) {
    const NodeId parent = nodes_[i].parent;
    const bool ordered = parent < i && (i == 1 || parent >= nodes_[i - 1].parent);
    if (!ordered) {
      throw InputError(source, "node " + std::to_string(i) + ": parent " + std::to_string(parent) +
                                   " out of breadth-first order");
    }
    Node& p = nodes_[parent];
    if (p.num_children == 0) p.first_child = static_cast<NodeId>(i);
    ++p.num_children;
    nodes_[i].depth = p.depth + 1;
    if (p.num_children > static_cast<std::uint32_t>(branching_) ||
        nodes_[i].depth > static_cast<std::uint32_t>(levels_)) {
      throw InputError(source, "node " + std::to_string(i) + " exceeds the branching k " +
                                   std::to_string(branching_) + " or the depth L " +
                                   std::to_string(levels_));
    }
  }
  for (std::size_t i = 1; i < nodes_.size(); ++i) {
    if (nodes_[i].num_children == 0) {
      nodes_[i].word = static_cast<WordId>(words_.size());
      words_.push_back(static_cast<NodeId>(i));
    }
  }
  if (words_.empty()) throw InputError(source, "vocabulary without words");
}

Vocabulary Vocabulary::Load(const std::filesystem::path& path) {
  RequireFile(path, "vocabulary");
  return FromBytes(ReadTextFile(path), path.string());
}

void Vocabulary::Save(const std::filesystem::path& path) const {
  WriteTextFileAtomically(path, ToBytes());
}

}  // namespace arucoslam
