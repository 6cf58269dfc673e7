// The vocabulary file: a versioned little-endian binary layout read with one
// pass of memcpy, so even a million-word tree loads in tens of milliseconds.
//
//   8 bytes   magic "PMVOCAB\0"
//   u32       format version (kVersion)
//   u32 x 5   branching, depth, dimension, node count, word count
//   f32       centre scale
//   arrays    first_child u32[n], child_count u16[n], word i32[n], parent u32[n],
//             centres u8[n * dimension], idf f32[w], leaf u32[w]
//   u64       checksum of everything from the version to the last array,
//             chained section by section (so loading reads each byte once)
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "patrolmap/core/checksum.h"
#include "patrolmap/core/files.h"
#include "patrolmap/vocab/vocabulary.h"

namespace patrolmap::vocab {
namespace {

constexpr float kMaxWordWeight = 100.0f;  // far above any idf a vocabulary can hold

constexpr char kMagic[8] = {'P', 'M', 'V', 'O', 'C', 'A', 'B', '\0'};
constexpr std::uint32_t kVersion = 1;
constexpr std::size_t kHeaderBytes = 8 + 4 * 6 + 4;

template <typename T>
void Append(const Array<T>& values, std::string* out) {
  out->append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
}

template <typename T>
void AppendValue(T value, std::string* out) {
  out->append(reinterpret_cast<const char*>(&value), sizeof(T));
}

// Reads `count` values straight into `values`, folding their bytes into the checksum.
template <typename T>
bool Take(std::ifstream* stream, std::size_t count, Array<T>* values, std::uint64_t* checksum) {
  values->resize(count);
  const std::size_t bytes = count * sizeof(T);
  if (!stream->read(reinterpret_cast<char*>(values->data()), static_cast<std::streamsize>(bytes))) return false;
  *checksum = Checksum(reinterpret_cast<const char*>(values->data()), bytes, *checksum);
  return true;
}

std::size_t BodyBytes(std::uint64_t nodes, std::uint64_t words, std::uint64_t dimension) {
  return nodes * (4 + 2 + 4 + 4 + dimension) + words * (4 + 4);
}

}  // namespace

// Befriended by Vocabulary to fill its arrays.
struct VocabularyFile {
  static Status Read(const std::string& path, Vocabulary* v) {
    std::error_code error;
    const std::uint64_t size = std::filesystem::file_size(path, error);
    if (error) return Status::NotFound(path + ": cannot read vocabulary: " + error.message());
    std::ifstream stream(path, std::ios::binary);
    char header[kHeaderBytes] = {};
    stream.read(header, static_cast<std::streamsize>(std::min<std::uint64_t>(size, kHeaderBytes)));
    if (size < 8 || std::memcmp(header, kMagic, 8) != 0)
      return Status::DataLoss(path + ": not a patrolmap vocabulary file");
    if (size < kHeaderBytes) return Status::DataLoss(path + ": truncated vocabulary (header incomplete)");
    std::uint32_t fields[6];
    std::memcpy(fields, header + 8, sizeof(fields));
    if (fields[0] > kVersion) {
      return Status::DataLoss(path + ": vocabulary format version " + std::to_string(fields[0]) +
                              " is newer than this patrolmap reads (" + std::to_string(kVersion) + ")");
    }
    const std::uint64_t nodes = fields[4], words = fields[5], dimension = fields[3];
    const std::uint64_t expected = kHeaderBytes + BodyBytes(nodes, words, dimension) + 8;
    if (size < expected) {
      return Status::DataLoss(path + ": truncated vocabulary (" + std::to_string(size) + " of " +
                              std::to_string(expected) + " bytes)");
    }
    if (size > expected) return Status::DataLoss(path + ": corrupt vocabulary (trailing bytes)");
    if (nodes == 0 || words == 0 || dimension == 0) return Status::DataLoss(path + ": corrupt vocabulary (empty tree)");
    *v = Vocabulary();
    v->branching_ = static_cast<int>(fields[1]);
    v->depth_ = static_cast<int>(fields[2]);
    v->dimension_ = static_cast<int>(dimension);
    std::memcpy(&v->scale_, header + 8 + 4 * 6, 4);
    std::uint64_t checksum = Checksum(header + 8, kHeaderBytes - 8, kChecksumSeed);
    const bool read = Take(&stream, nodes, &v->first_child_, &checksum) &&
                      Take(&stream, nodes, &v->child_count_, &checksum) && Take(&stream, nodes, &v->word_, &checksum) &&
                      Take(&stream, nodes, &v->parent_, &checksum) &&
                      Take(&stream, nodes * dimension, &v->centres_, &checksum) &&
                      Take(&stream, words, &v->idf_, &checksum) && Take(&stream, words, &v->leaf_, &checksum);
    std::uint64_t stored = 0;
    if (!read || !stream.read(reinterpret_cast<char*>(&stored), 8)) return Status::IoError(path + ": read failed");
    if (stored != checksum) return Status::DataLoss(path + ": corrupt vocabulary (checksum mismatch)");
    return Validate(path, *v);
  }

  // Links must stay inside the arrays, so a file with a good checksum but bad content cannot crash lookups.
  static Status Validate(const std::string& path, const Vocabulary& v) {
    const std::size_t nodes = v.first_child_.size(), words = v.idf_.size();
    for (std::size_t n = 0; n < nodes; ++n) {
      const bool leaf = v.child_count_[n] == 0;
      const std::uint64_t end = static_cast<std::uint64_t>(v.first_child_[n]) + v.child_count_[n];  // no 32-bit wrap
      if (!leaf && (v.first_child_[n] <= n || end > nodes)) {
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
    for (float idf : v.idf_) {
      // idf = ln(N / n) of at most 2^32 training images is below 23; a weight of 3e38 overflows the BoW scores.
      if (!std::isfinite(idf) || idf < 0.0f || idf > kMaxWordWeight) {
        return Status::DataLoss(path + ": corrupt vocabulary (word weight)");
      }
    }
    if (!std::isfinite(v.scale_) || !(v.scale_ > 0.0f)) return Status::DataLoss(path + ": corrupt vocabulary (scale)");
    return Status::Ok();
  }

  static std::string Serialise(const Vocabulary& v) {
    std::string out(kMagic, 8);
    out.reserve(kHeaderBytes + BodyBytes(v.first_child_.size(), v.idf_.size(), v.dimension_) + 8);
    for (std::uint32_t value :
         {kVersion, static_cast<std::uint32_t>(v.branching_), static_cast<std::uint32_t>(v.depth_),
          static_cast<std::uint32_t>(v.dimension_), static_cast<std::uint32_t>(v.first_child_.size()),
          static_cast<std::uint32_t>(v.idf_.size())}) {
      AppendValue(value, &out);
    }
    AppendValue(v.scale_, &out);
    std::uint64_t checksum = Checksum(out.data() + 8, out.size() - 8, kChecksumSeed);
    const auto section = [&out, &checksum](const auto& values) {
      const std::size_t start = out.size();
      Append(values, &out);
      checksum = Checksum(out.data() + start, out.size() - start, checksum);
    };
    section(v.first_child_);
    section(v.child_count_);
    section(v.word_);
    section(v.parent_);
    section(v.centres_);
    section(v.idf_);
    section(v.leaf_);
    AppendValue(checksum, &out);
    return out;
  }
};

Status Vocabulary::Save(const std::string& path) const {
  if (empty()) return Status::InvalidArgument(path + ": cannot save an empty vocabulary");
  return WriteFileAtomically(path, VocabularyFile::Serialise(*this));
}

Status Vocabulary::Load(const std::string& path, Vocabulary* vocabulary) {
  return VocabularyFile::Read(path, vocabulary);
}

}  // namespace patrolmap::vocab
