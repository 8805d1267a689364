// FrameSource: one streaming interface over everything `run` reads — the file sequences of
// Dataset (EuRoC, TUM RGB-D, KITTI, image folder), video files and live cameras. Next() hands
// out grey frames in time order until the end (or a stop request for a live camera).
#pragma once

#include <cstddef>
#include <filesystem>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <utility>

#include "arucoslam/geometry/camera.h"
#include "arucoslam/io/dataset_reader.h"
#include "arucoslam/io/trajectory_io.h"

namespace arucoslam {

struct SourceFrame {
  std::size_t index = 0;     // 0-based position among the frames handed out
  double timestamp_s = 0.0;  // strictly increasing
  cv::Mat image;             // 8-bit grey, the camera's size
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;

  // The next frame; nullopt at the end. Throws InputError naming the file when a frame that
  // should be there cannot be read.
  virtual std::optional<SourceFrame> Next() = 0;

  virtual const CameraModel& camera() const = 0;
  // "euroc", "tum", "kitti", "images", "video" or "camera", as stats.json records it.
  virtual std::string layout() const = 0;
  // Frames in the whole source where known in advance (progress lines), else nullopt.
  virtual std::optional<std::size_t> size() const { return std::nullopt; }
  // The sequence's marker map (SEQ/markers.json) where it has one.
  virtual std::optional<std::filesystem::path> markers_path() const { return std::nullopt; }
  // A live source captures whether or not Next() is called and drops what it cannot hand out.
  virtual bool live() const { return false; }
  // Frames captured but never handed out (live sources only).
  virtual std::size_t frames_dropped() const { return 0; }
};

// A FrameSource that hands out the frames of a recorded one in its own way (paced, read
// ahead); what describes the source (camera, layout, size, marker map) is the recorded one's.
class WrappingSource : public FrameSource {
 public:
  explicit WrappingSource(std::unique_ptr<FrameSource> recorded) : recorded_(std::move(recorded)) {}
  const CameraModel& camera() const override { return recorded_->camera(); }
  std::string layout() const override { return recorded_->layout(); }
  std::optional<std::size_t> size() const override { return recorded_->size(); }
  std::optional<std::filesystem::path> markers_path() const override {
    return recorded_->markers_path();
  }

 protected:
  FrameSource& recorded() { return *recorded_; }
  const FrameSource& recorded() const { return *recorded_; }

 private:
  std::unique_ptr<FrameSource> recorded_;
};

// A Dataset as a FrameSource (images loaded one at a time, as Next() asks).
class DatasetSource : public FrameSource {
 public:
  explicit DatasetSource(Dataset dataset) : dataset_(std::move(dataset)) {}

  std::optional<SourceFrame> Next() override;
  const CameraModel& camera() const override { return dataset_.camera(); }
  std::string layout() const override { return DatasetLayoutName(dataset_.layout()); }
  std::optional<std::size_t> size() const override { return dataset_.size(); }
  std::optional<std::filesystem::path> markers_path() const override {
    return dataset_.markers_path();
  }
  const Dataset& dataset() const { return dataset_; }

 private:
  Dataset dataset_;
  std::size_t next_ = 0;
};

// Opens `path`: a folder through Dataset::Open (any of its layouts), a regular file as a video
// (io/video_source.h; options.camera_path is then required and options.rate_hz, when set,
// replaces the container's timestamps). Throws InputError naming the path: missing, a file
// that is not a video, a folder of no known layout, and Dataset::Open's errors.
std::unique_ptr<FrameSource> OpenFrameSource(const std::filesystem::path& path,
                                             const DatasetOptions& options = {});

}  // namespace arucoslam
