#pragma once
// The camera image pane: shows a BGR/gray cv::Mat in its viewport, scaled to fit with
// the aspect ratio kept (zoom and pan allowed), and converts between window (display)
// pixels and source-image pixels — the mapping box selection relies on.
#include <vtkImageActor.h>
#include <vtkImageData.h>
#include <vtkRenderer.h>
#include <vtkSmartPointer.h>

#include <opencv2/core.hpp>
#include <optional>

namespace aerie::viewer {

class ImagePane {
 public:
  explicit ImagePane(vtkRenderer* renderer);

  void show(const cv::Mat& image);  // 8-bit gray or BGR
  cv::Size image_size() const { return size_; }
  // Fits the image in the viewport (undoes zoom/pan).
  void reset_view();
  // Zooms about the viewport centre (factor > 1 enlarges).
  void zoom(double factor);

  // Display coordinates (VTK: origin bottom-left of the window, pixels) to image pixel
  // coordinates (origin top-left of the image); nullopt outside the pane's viewport.
  std::optional<cv::Point2d> display_to_image(double x, double y) const;
  cv::Point2d image_to_display(const cv::Point2d& uv) const;
  bool contains_display(double x, double y) const;

 private:
  vtkRenderer* renderer_;
  vtkSmartPointer<vtkImageData> data_;
  vtkSmartPointer<vtkImageActor> actor_;
  cv::Size size_;
};

}  // namespace aerie::viewer
