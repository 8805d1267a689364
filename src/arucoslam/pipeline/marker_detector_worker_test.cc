#include "arucoslam/pipeline/marker_detector_worker.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "arucoslam/markers/synthetic_view.h"

namespace arucoslam {
namespace {

// Three markers facing the camera at 1.5 to 2.5 m, at different places in the view.
cv::Mat ThreeMarkerView(int first_id) {
  std::vector<SyntheticMarker> markers;
  const Eigen::Matrix3d facing = Eigen::Vector3d(1, -1, -1).asDiagonal();
  for (int i = 0; i < 3; ++i) {
    SyntheticMarker marker;
    marker.id = first_id + i;
    marker.cam_from_marker = Rigid3(facing, Eigen::Vector3d(-0.6 + 0.6 * i, 0.1 * i, 1.5 + 0.5 * i));
    markers.push_back(marker);
  }
  return RenderSyntheticView(SyntheticCamera640(), markers);
}

// The worker gives what Detect gives on the caller's thread, image after image.
TEST(MarkerDetectorWorkerTest, SameDetectionsAsDetect) {
  const MarkerDetector detector;
  MarkerDetectorWorker worker(detector);
  for (int first_id = 0; first_id < 12; first_id += 3) {
    const cv::Mat image = ThreeMarkerView(first_id);
    const std::vector<MarkerDetection> expected = detector.Detect(image);
    ASSERT_EQ(expected.size(), 3u);
    worker.Start(image);
    const TimedDetections result = worker.Wait();
    ASSERT_EQ(result.detections.size(), expected.size());
    for (std::size_t i = 0; i < expected.size(); ++i) {
      EXPECT_EQ(result.detections[i].id, expected[i].id);
      EXPECT_EQ(result.detections[i].id, first_id + static_cast<int>(i));
      for (int k = 0; k < 4; ++k) {
        EXPECT_EQ(result.detections[i].corners[k], expected[i].corners[k]);
      }
    }
    EXPECT_GT(result.wall_ms, 0.0);
    EXPECT_GE(result.cpu_ms, 0.0);
  }
}

// With regions, the worker gives what DetectInRegions gives: here the left half only.
TEST(MarkerDetectorWorkerTest, RegionsAsDetectInRegions) {
  const MarkerDetector detector;
  MarkerDetectorWorker worker(detector);
  const cv::Mat image = ThreeMarkerView(0);
  const std::vector<cv::Rect> left = {cv::Rect(0, 0, 320, 480)};
  const std::vector<MarkerDetection> expected = detector.DetectInRegions(image, left);
  ASSERT_EQ(expected.size(), 1u);  // the marker at x = -0.6 m
  worker.Start(image, left);
  const std::vector<MarkerDetection> found = worker.Wait().detections;
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].id, 0);
  for (int k = 0; k < 4; ++k) EXPECT_EQ(found[0].corners[k], expected[0].corners[k]);
}

TEST(MarkerDetectorWorkerTest, ErrorsReachTheCaller) {
  const MarkerDetector detector;
  MarkerDetectorWorker worker(detector);
  EXPECT_THROW(worker.Wait(), std::logic_error);  // nothing started
  worker.Start(cv::Mat(480, 640, CV_16U, cv::Scalar(0)));  // Detect rejects 16-bit images
  EXPECT_THROW(worker.Start(ThreeMarkerView(0)), std::logic_error);  // not waited for
  EXPECT_THROW(worker.Wait(), std::invalid_argument);
  worker.Start(ThreeMarkerView(0));  // usable again after the error
  EXPECT_EQ(worker.Wait().detections.size(), 3u);
}

}  // namespace
}  // namespace arucoslam
