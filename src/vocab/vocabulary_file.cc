// The vocabulary file: a versioned little-endian binary layout read with one
// pass of memcpy, so even a million-word tree loads in tens of milliseconds.
//
//   8 bytes   magic "PMVOCAB\0"
//   u32       format version (kVersion)
//   u32 x 5   branching, depth, dimension, node count, word count
//   f32       centre scale
//   arrays    first_child u32[n], child_count u16[n], word i32[n], parent u32[n],
//             centres u8[n * dimension], idf f32[w], leaf u32[w]
//   u64       checksum of everything from the version to the last array
#include <cstring>
#include <filesystem>
#include <fstream>

#include "patrolmap/core/files.h"
#include "patrolmap/vocab/vocabulary.h"

namespace patrolmap::vocab {
namespace {

constexpr char kMagic[8] = {'P', 'M', 'V', 'O', 'C', 'A', 'B', '\0'};
constexpr std::uint32_t kVersion = 1;
constexpr std::size_t kHeaderBytes = 8 + 4 * 6 + 4;

// A fast 64-bit checksum over 8-byte words (and the tail bytes).
std::uint64_t Checksum(const char* data, std::size_t size) {
  std::uint64_t hash = 0x9E3779B97F4A7C15ull ^ size;
  std::size_t i = 0;
  for (; i + 8 <= size; i += 8) {
    std::uint64_t word;
    std::memcpy(&word, data + i, 8);
    hash = (hash ^ word) * 0xFF51AFD7ED558CCDull;
    hash ^= hash >> 29;
  }
  for (; i < size; ++i) hash = (hash ^ static_cast<unsigned char>(data[i])) * 0x100000001B3ull;
  return hash;
}

template <typename T>
void Append(const std::vector<T>& values, std::string* out) {
  out->append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
}

template <typename T>
void AppendValue(T value, std::string* out) {
  out->append(reinterpret_cast<const char*>(&value), sizeof(T));
}

template <typename T>
void Take(const char** cursor, std::size_t count, std::vector<T>* values) {
  values->resize(count);
  std::memcpy(values->data(), *cursor, count * sizeof(T));
  *cursor += count * sizeof(T);
}

std::size_t BodyBytes(std::uint64_t nodes, std::uint64_t words, std::uint64_t dimension) {
  return nodes * (4 + 2 + 4 + 4 + dimension) + words * (4 + 4);
}

Status ReadWhole(const std::string& path, std::string* bytes) {
  std::error_code error;
  const auto size = std::filesystem::file_size(path, error);
  if (error) return Status::NotFound(path + ": cannot read vocabulary: " + error.message());
  std::ifstream stream(path, std::ios::binary);
  bytes->resize(size);
  if (!stream.read(bytes->data(), static_cast<std::streamsize>(size))) return Status::IoError(path + ": read failed");
  return Status::Ok();
}

}  // namespace

// Befriended by Vocabulary to fill its arrays.
struct VocabularyFile {
  static Status Parse(const std::string& path, const std::string& bytes, Vocabulary* v) {
    if (bytes.size() < 8 || std::memcmp(bytes.data(), kMagic, 8) != 0) {
      return Status::DataLoss(path + ": not a patrolmap vocabulary file");
    }
    if (bytes.size() < kHeaderBytes) return Status::DataLoss(path + ": truncated vocabulary (header incomplete)");
    std::uint32_t header[6];
    std::memcpy(header, bytes.data() + 8, sizeof(header));
    if (header[0] > kVersion) {
      return Status::DataLoss(path + ": vocabulary format version " + std::to_string(header[0]) +
                              " is newer than this patrolmap reads (" + std::to_string(kVersion) + ")");
    }
    const std::uint64_t nodes = header[4], words = header[5], dimension = header[3];
    const std::size_t expected = kHeaderBytes + BodyBytes(nodes, words, dimension) + 8;
    if (bytes.size() < expected) {
      return Status::DataLoss(path + ": truncated vocabulary (" + std::to_string(bytes.size()) + " of " +
                              std::to_string(expected) + " bytes)");
    }
    if (bytes.size() > expected) return Status::DataLoss(path + ": corrupt vocabulary (trailing bytes)");
    std::uint64_t stored;
    std::memcpy(&stored, bytes.data() + expected - 8, 8);
    if (stored != Checksum(bytes.data() + 8, expected - 16)) {
      return Status::DataLoss(path + ": corrupt vocabulary (checksum mismatch)");
    }
    if (nodes == 0 || words == 0 || dimension == 0) return Status::DataLoss(path + ": corrupt vocabulary (empty tree)");
    *v = Vocabulary();
    v->branching_ = static_cast<int>(header[1]);
    v->depth_ = static_cast<int>(header[2]);
    v->dimension_ = static_cast<int>(dimension);
    std::memcpy(&v->scale_, bytes.data() + 8 + 4 * 6, 4);
    const char* cursor = bytes.data() + kHeaderBytes;
    Take(&cursor, nodes, &v->first_child_);
    Take(&cursor, nodes, &v->child_count_);
    Take(&cursor, nodes, &v->word_);
    Take(&cursor, nodes, &v->parent_);
    Take(&cursor, nodes * dimension, &v->centres_);
    Take(&cursor, words, &v->idf_);
    Take(&cursor, words, &v->leaf_);
    return Validate(path, *v);
  }

  // Links must stay inside the arrays, so a file with a good checksum but bad content cannot crash lookups.
  static Status Validate(const std::string& path, const Vocabulary& v) {
    const std::size_t nodes = v.first_child_.size(), words = v.idf_.size();
    for (std::size_t n = 0; n < nodes; ++n) {
      const bool leaf = v.child_count_[n] == 0;
      if (!leaf && (v.first_child_[n] <= n || v.first_child_[n] + v.child_count_[n] > nodes)) {
        return Status::DataLoss(path + ": corrupt vocabulary (child link of node " + std::to_string(n) + ")");
      }
      if (leaf != (v.word_[n] >= 0) || (leaf && static_cast<std::size_t>(v.word_[n]) >= words)) {
        return Status::DataLoss(path + ": corrupt vocabulary (word of node " + std::to_string(n) + ")");
      }
      if (v.parent_[n] >= nodes) return Status::DataLoss(path + ": corrupt vocabulary (parent link)");
    }
    for (std::uint32_t leaf : v.leaf_) {
      if (leaf >= nodes) return Status::DataLoss(path + ": corrupt vocabulary (leaf link)");
    }
    return Status::Ok();
  }

  static std::string Serialise(const Vocabulary& v) {
    std::string out(kMagic, 8);
    out.reserve(kHeaderBytes + BodyBytes(v.first_child_.size(), v.idf_.size(), v.dimension_) + 8);
    for (std::uint32_t value : {kVersion, static_cast<std::uint32_t>(v.branching_), static_cast<std::uint32_t>(v.depth_),
                                static_cast<std::uint32_t>(v.dimension_), static_cast<std::uint32_t>(v.first_child_.size()),
                                static_cast<std::uint32_t>(v.idf_.size())}) {
      AppendValue(value, &out);
    }
    AppendValue(v.scale_, &out);
    Append(v.first_child_, &out);
    Append(v.child_count_, &out);
    Append(v.word_, &out);
    Append(v.parent_, &out);
    Append(v.centres_, &out);
    Append(v.idf_, &out);
    Append(v.leaf_, &out);
    AppendValue(Checksum(out.data() + 8, out.size() - 8), &out);
    return out;
  }
};

Status Vocabulary::Save(const std::string& path) const {
  if (empty()) return Status::InvalidArgument(path + ": cannot save an empty vocabulary");
  return WriteFileAtomically(path, VocabularyFile::Serialise(*this));
}

Status Vocabulary::Load(const std::string& path, Vocabulary* vocabulary) {
  std::string bytes;
  PATROLMAP_RETURN_IF_ERROR(ReadWhole(path, &bytes));
  return VocabularyFile::Parse(path, bytes, vocabulary);
}

}  // namespace patrolmap::vocab
