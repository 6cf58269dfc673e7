// Fuzzes the vocabulary file reader and, when a file loads, quantises a few descriptors with it.
#include <cstddef>
#include <cstdint>

#include <opencv2/core.hpp>

#include "fuzz_files.h"
#include "patrolmap/vocab/vocabulary.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto folder = patrolmap::fuzz::FreshFolder();
  patrolmap::fuzz::WriteBytes(folder / "in.pmvoc", {reinterpret_cast<const char*>(data), size});
  patrolmap::vocab::Vocabulary vocabulary;
  if (!patrolmap::vocab::Vocabulary::Load((folder / "in.pmvoc").string(), &vocabulary).ok()) return 0;
  cv::Mat descriptors(3, vocabulary.dimension(), CV_32F);
  cv::randu(descriptors, 0.0f, 1.0f);
  patrolmap::vocab::BowVector bow;
  vocabulary.Transform(descriptors, &bow);
  return 0;
}
