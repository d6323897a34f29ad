#include "ground/viewer/layout.hpp"

namespace aerie::viewer {

Layout Layout::create(int width, int height, bool offscreen, int multisamples) {
  Layout l;
  l.window = vtkSmartPointer<vtkRenderWindow>::New();
  l.window->SetSize(width, height);
  l.window->SetWindowName("Aerie ground viewer");
  if (offscreen) l.window->SetOffScreenRendering(1);
  l.window->SetMultiSamples(multisamples);
  auto make = [&](double x0, double y0, double x1, double y1, double r, double g, double b) {
    auto ren = vtkSmartPointer<vtkRenderer>::New();
    ren->SetViewport(x0, y0, x1, y1);
    ren->SetBackground(r, g, b);
    l.window->AddRenderer(ren);
    return ren;
  };
  l.image = make(0.0, 0.42, 0.46, 1.0, 0.08, 0.08, 0.08);
  l.scene = make(0.46, 0.42, 1.0, 1.0, 0.12, 0.14, 0.18);
  l.panel = make(0.76, 0.0, 1.0, 0.42, 0.05, 0.05, 0.07);
  for (size_t i = 0; i < l.charts.size(); ++i) {
    const double col = static_cast<double>(i % 3), row = static_cast<double>(1 - i / 3);
    l.charts[i] = make(col * 0.2533, row * 0.21, (col + 1) * 0.2533, (row + 1) * 0.21, 1, 1, 1);
  }
  return l;
}

}  // namespace aerie::viewer
