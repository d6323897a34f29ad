#pragma once
// The viewer window: one vtkRenderWindow split into viewports — the camera image pane
// (top left), the 3D scene (top right), a grid of charts (bottom) and a text panel
// (bottom right: procman and status).
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkSmartPointer.h>

#include <array>

namespace aerie::viewer {

enum class ChartSlot { Heading = 0, Tracker, VoFeatures, Latency, CeCost, CePdf, Count };

struct Layout {
  vtkSmartPointer<vtkRenderWindow> window;
  vtkSmartPointer<vtkRenderer> image;
  vtkSmartPointer<vtkRenderer> scene;
  vtkSmartPointer<vtkRenderer> panel;
  std::array<vtkSmartPointer<vtkRenderer>, static_cast<size_t>(ChartSlot::Count)> charts;

  vtkRenderer* chart(ChartSlot s) const { return charts[static_cast<size_t>(s)]; }
  static Layout create(int width, int height, bool offscreen, int multisamples = 0);
};

}  // namespace aerie::viewer
