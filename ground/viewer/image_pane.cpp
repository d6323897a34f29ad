#include "ground/viewer/image_pane.hpp"

#include <vtkCamera.h>
#include <vtkImageMapper3D.h>
#include <vtkRenderWindow.h>

#include <algorithm>
#include <cstring>
#include <opencv2/imgproc.hpp>

namespace aerie::viewer {

ImagePane::ImagePane(vtkRenderer* renderer) : renderer_(renderer) {
  data_ = vtkSmartPointer<vtkImageData>::New();
  actor_ = vtkSmartPointer<vtkImageActor>::New();
  actor_->GetMapper()->SetInputData(data_);
  actor_->InterpolateOff();
  actor_->VisibilityOff();
  renderer_->AddActor(actor_);
  renderer_->GetActiveCamera()->ParallelProjectionOn();
}

void ImagePane::show(const cv::Mat& image) {
  cv::Mat rgb;
  if (image.channels() == 1)
    cv::cvtColor(image, rgb, cv::COLOR_GRAY2RGB);
  else
    cv::cvtColor(image, rgb, cv::COLOR_BGR2RGB);
  const bool resized = rgb.size() != size_;
  if (resized) {
    size_ = rgb.size();
    data_->SetDimensions(size_.width, size_.height, 1);
    data_->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
  }
  // VTK's image origin is bottom-left: world (x, y) = (u, H - 1 - v).
  auto* dst = static_cast<unsigned char*>(data_->GetScalarPointer());
  const size_t row = static_cast<size_t>(size_.width) * 3;
  for (int v = 0; v < size_.height; ++v) std::memcpy(dst + (size_.height - 1 - v) * row, rgb.ptr(v), row);
  data_->Modified();
  actor_->VisibilityOn();
  if (resized) reset_view();
}

void ImagePane::reset_view() {
  if (size_.empty()) return;
  vtkCamera* cam = renderer_->GetActiveCamera();
  const double cx = (size_.width - 1) / 2.0, cy = (size_.height - 1) / 2.0;
  cam->SetFocalPoint(cx, cy, 0);
  cam->SetPosition(cx, cy, 1000);
  cam->SetViewUp(0, 1, 0);
  // Parallel scale is half the visible height in world units: fit the image, keep aspect.
  int* win = renderer_->GetRenderWindow() ? renderer_->GetRenderWindow()->GetSize() : nullptr;
  double vp[4];
  renderer_->GetViewport(vp);
  double aspect = 1.0;
  if (win && win[0] > 0 && win[1] > 0) aspect = ((vp[2] - vp[0]) * win[0]) / ((vp[3] - vp[1]) * win[1]);
  const double half_h = size_.height / 2.0, half_w = size_.width / 2.0;
  cam->SetParallelScale(std::max(half_h, half_w / aspect));
  renderer_->ResetCameraClippingRange();
}

void ImagePane::zoom(double factor) { renderer_->GetActiveCamera()->Zoom(factor); }

bool ImagePane::contains_display(double x, double y) const { return renderer_->IsInViewport(static_cast<int>(x), static_cast<int>(y)); }

std::optional<cv::Point2d> ImagePane::display_to_image(double x, double y) const {
  if (!contains_display(x, y) || size_.empty()) return std::nullopt;
  renderer_->SetDisplayPoint(x, y, 0);
  renderer_->DisplayToWorld();
  double w[4];
  renderer_->GetWorldPoint(w);
  if (w[3] != 0) {
    w[0] /= w[3];
    w[1] /= w[3];
  }
  return cv::Point2d(w[0], size_.height - 1 - w[1]);
}

cv::Point2d ImagePane::image_to_display(const cv::Point2d& uv) const {
  renderer_->SetWorldPoint(uv.x, size_.height - 1 - uv.y, 0, 1);
  renderer_->WorldToDisplay();
  double d[3];
  renderer_->GetDisplayPoint(d);
  return {d[0], d[1]};
}

}  // namespace aerie::viewer
