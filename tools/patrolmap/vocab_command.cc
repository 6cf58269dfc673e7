// patrolmap vocab build INPUTS... --out FILE [-k K] [-L L] [--every N] [--seed S]
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "commands.h"
#include "common.h"
#include "patrolmap/core/files.h"
#include "patrolmap/io/readers.h"
#include "patrolmap/place/place_recognizer.h"
#include "patrolmap/vocab/vocabulary.h"
#include "progress.h"

namespace patrolmap::tools {
namespace {

struct VocabArguments {
  std::vector<std::string> inputs;
  std::string out;
  std::string config;
  std::vector<std::string> settings;  // --set KEY=VALUE
  int every = 15;
  vocab::VocabularyOptions options;
};

// Photographs given one by one (any size) are described at this width, about that of key frames at the
// flow stage's scale [pixels].
constexpr int kPhotoWidth = 640;

bool IsPhotograph(const std::string& input) {
  static const std::vector<std::string> kExtensions = {".jpg", ".jpeg", ".png", ".webp", ".bmp", ".tif", ".tiff"};
  std::string extension = std::filesystem::path(input).extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return std::filesystem::is_regular_file(input) &&
         std::find(kExtensions.begin(), kExtensions.end(), extension) != kExtensions.end();
}

// Features of one photograph at kPhotoWidth.
Status CollectPhotograph(const std::string& input, const pipeline::Config& config, std::vector<cv::Mat>* images) {
  const cv::Mat image = cv::imread(input, cv::IMREAD_GRAYSCALE);
  if (image.empty()) return Status::DataLoss(input + ": not an image OpenCV can read");
  cv::Mat small;
  const double scale = static_cast<double>(kPhotoWidth) / image.cols;
  cv::resize(image, small, cv::Size(), scale, scale, scale < 1.0 ? cv::INTER_AREA : cv::INTER_LINEAR);
  std::vector<cv::Point2f> points;
  cv::Mat descriptors;
  place::DescribeFeatures(small, config.place, &points, &descriptors);
  images->push_back(descriptors);
  return Status::Ok();
}

// Features of every `every`-th frame of a log, at the flow stage's scale.
Status CollectFeatures(const std::string& input, const VocabArguments& arguments, const pipeline::Config& config,
                       std::vector<cv::Mat>* images) {
  std::unique_ptr<io::FrameSource> source;
  PATROLMAP_RETURN_IF_ERROR(io::OpenLog(input, config.input, &source));
  Progress progress("features");
  Frame frame;
  Status status;
  std::int64_t next = 0;
  cv::Mat small;
  while ((status = source->Next(next % arguments.every == 0, &frame)).ok()) {
    next = frame.index + 1;
    if (frame.image.empty() || frame.index % arguments.every != 0) continue;
    cv::resize(frame.image, small, cv::Size(), config.flow.frames.scale, config.flow.frames.scale, cv::INTER_AREA);
    std::vector<cv::Point2f> points;
    cv::Mat descriptors;
    place::DescribeFeatures(small, config.place, &points, &descriptors);
    images->push_back(descriptors);
    progress.Update(frame.index, source->info().frame_count);
  }
  return status.end_of_stream() ? Status::Ok() : status;
}

int RunBuild(const VocabArguments& arguments) {
  pipeline::Config config;
  Status status = RefuseOverwritingInput(arguments.out, arguments.config, "configuration");
  for (std::size_t i = 0; status.ok() && i < arguments.inputs.size(); ++i) {
    status = RefuseOverwritingInput(arguments.out, arguments.inputs[i], "training input");
  }
  if (status.ok()) status = LoadCheckedConfig(arguments.config, arguments.settings, &config);
  std::vector<cv::Mat> images;
  for (std::size_t i = 0; status.ok() && i < arguments.inputs.size(); ++i) {
    const std::string& input = arguments.inputs[i];
    status = IsPhotograph(input) ? CollectPhotograph(input, config, &images)
                                 : CollectFeatures(input, arguments, config, &images);
  }
  std::size_t descriptors = 0;
  for (const cv::Mat& image : images) descriptors += image.rows;
  vocab::Vocabulary vocabulary;
  if (status.ok()) {
    Progress progress("train");
    status = vocab::Vocabulary::Train(images, arguments.options, &vocabulary,
                                      [&progress](std::size_t d, std::size_t t) { progress.Update(d, t); });
  }
  if (status.ok()) status = vocabulary.Save(arguments.out);
  if (!status.ok()) return Fail(status);
  std::printf("%s: %d words (k=%d, L=%d) from %zu descriptors of %zu images\n", arguments.out.c_str(),
              vocabulary.word_count(), arguments.options.branching, arguments.options.depth, descriptors,
              images.size());
  return 0;
}

}  // namespace

Command AddVocabCommand(CLI::App* app) {
  auto arguments = std::make_shared<VocabArguments>();
  app->require_subcommand(1);
  CLI::App* build =
      app->add_subcommand("build", "train a vocabulary tree on the SIFT features of logs or image folders");
  build
      ->add_option("inputs", arguments->inputs,
                   "logs, image folders, patterns or videos (every n-th frame), or single photographs (each "
                   "described at " +
                       std::to_string(kPhotoWidth) + " pixels wide)")
      ->required();
  build->add_option("-o,--out", arguments->out, "vocabulary file to write")->required();
  build->add_option("-c,--config", arguments->config,
                    "YAML configuration (features: place.*, scale: flow.frames.scale)");
  AddSetOption(build, &arguments->settings);
  build->add_option("-k,--branching", arguments->options.branching, "children per node")->capture_default_str();
  build->add_option("-L,--depth", arguments->options.depth, "levels below the root")->capture_default_str();
  build->add_option("--every", arguments->every, "use every n-th frame")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  build->add_option("--seed", arguments->options.seed, "k-means++ seed")->capture_default_str();
  build->add_option("--max-iterations", arguments->options.max_iterations, "k-means iteration cap per node")
      ->capture_default_str();
  return [arguments] { return RunBuild(*arguments); };
}

}  // namespace patrolmap::tools
