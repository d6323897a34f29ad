// Each renderer fed with known messages renders the expected content: the tests read
// pixels of the snapshot, not just that a file exists.
#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include <dlfcn.h>
#include <link.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <thread>

#include <aerie/autopilot_state_t.hpp>
#include <aerie/control_cmd_t.hpp>
#include <aerie/process_status_t.hpp>
#include <bot_procman/info2_t.hpp>
#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkCommand.h>
#include <vtkImageData.h>
#include <vtkWindowToImageFilter.h>

#include "air/track/factory.hpp"
#include "air/track/node/default_tracker.hpp"
#include "common/image/image_message.hpp"
#include "common/util/time.hpp"
#include "ground/map/octomap_message.hpp"
#include "procman/channels.hpp"
#include "ground/viewer/keys.hpp"
#include "ground/viewer/renderers/charts.hpp"
#include "ground/viewer/renderers/panel.hpp"
#include "ground/viewer/renderers/scene.hpp"
#include "ground/viewer/viewer.hpp"
#include "tests/support/test_support.hpp"

using namespace aerie;
using namespace aerie::viewer;

namespace {

// Mesa's GL driver (swrast_dri.so under Xvfb) is unloaded when the last window closes, with
// blocks it still holds through its own globals; LeakSanitizer then reports them as leaks of
// "<unknown module>" at exit. Pinning every loaded *_dri.so (RTLD_NODELETE) keeps those
// globals mapped, so LSan sees the blocks as reachable; nothing else changes.
void pin_gl_drivers() {
  dl_iterate_phdr(
      [](dl_phdr_info* info, size_t, void*) {
        const char* name = info->dlpi_name;
        const size_t n = name ? std::strlen(name) : 0;
        if (n > 7 && std::strcmp(name + n - 7, "_dri.so") == 0) dlopen(name, RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);
        return 0;
      },
      nullptr);
}

struct Fixture : ::testing::Test {
  std::unique_ptr<bus::Bus> bus_ptr = std::make_unique<bus::Bus>("memq://");
  bus::Bus& bus = *bus_ptr;
  std::unique_ptr<Viewer> viewer;

  void make(int w = 1280, int h = 800) { viewer = make_viewer(bus, w, h); }
  static std::unique_ptr<Viewer> make_viewer(bus::Bus& b, int w, int h) {
    ViewerOptions o;
    o.width = w;
    o.height = h;
    o.offscreen = true;
    auto v = std::make_unique<Viewer>(b, o);
    v->add_default_renderers();
    v->start();
    return v;
  }
  void TearDown() override {
    pin_gl_drivers();
    if (viewer) viewer->stop();
  }
  // Renders until `done` holds (the LCM thread delivers asynchronously), at most 3 s.
  template <typename F>
  bool render_until(F done) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(3);
    while (std::chrono::steady_clock::now() < end) {
      viewer->render_frame();
      if (done()) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  }
  cv::Mat snapshot() {
    const auto file = aerie::test::scratch_dir("snap") / "viewer.png";
    viewer->snapshot(file.string());
    cv::Mat img = cv::imread(file.string(), cv::IMREAD_COLOR);
    EXPECT_FALSE(img.empty());
    return img;
  }
  // Window pixel (PNG, origin top-left) of an image-pane pixel.
  cv::Point window_pixel_of_image(const cv::Point2d& uv) {
    const cv::Point2d d = viewer->image_pane().image_to_display(uv);
    return {cvRound(d.x), viewer->layout().window->GetSize()[1] - 1 - cvRound(d.y)};
  }
  void publish_image(int64_t utime, uchar value = 90) { publish_image_on(bus, utime, value); }
  void publish_map(octomap::OcTree& tree, int64_t utime) {
    tree.updateInnerOccupancy();
    aerie::octomap_t m{};
    m.utime = utime;
    m.full = true;
    map::encode_octree(tree, true, m);
    bus.publish("MAP_OCTOMAP", m);
  }
  static void publish_image_on(bus::Bus& b, int64_t utime, uchar value = 90) {
    b.publish("CAM_LEFT", image::to_message(cv::Mat(240, 320, CV_8UC1, cv::Scalar(value)), utime, utime));
  }
};

bool near_color(const cv::Mat& img, cv::Point p, const cv::Vec3b& bgr, int radius = 2, int tol = 40) {
  for (int dy = -radius; dy <= radius; ++dy)
    for (int dx = -radius; dx <= radius; ++dx) {
      const cv::Point q = p + cv::Point(dx, dy);
      if (!cv::Rect({}, img.size()).contains(q)) continue;
      const cv::Vec3b c = img.at<cv::Vec3b>(q);
      if (std::abs(c[0] - bgr[0]) < tol && std::abs(c[1] - bgr[1]) < tol && std::abs(c[2] - bgr[2]) < tol) return true;
    }
  return false;
}

aerie::track_t box_track(int64_t utime, double x0, double y0, double x1, double y1) {
  aerie::track_t t{};
  t.utime = utime;
  t.tracker = "ct";
  t.status = aerie::track_t::TRACKING;
  t.x = (x0 + x1) / 2;
  t.y = (y0 + y1) / 2;
  t.scale = 1;
  t.width = x1 - x0;
  t.height = y1 - y0;
  const double c[4][2] = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
  for (int i = 0; i < 4; ++i) {
    t.corners[i][0] = c[i][0];
    t.corners[i][1] = c[i][1];
  }
  t.confidence = 0.9f;
  t.nlevels = 0;
  return t;
}

// A door half's status as tools/link/door_node.cpp publishes it (refresh_status, status_line).
aerie::process_status_t door_status(const char* half, const char* fingerprint, int64_t epoch = 3) {
  aerie::process_status_t m{};
  m.utime = util::wall_utime();
  m.node = std::string("link-") + half;
  m.host = half;
  m.pid = 1;
  const bool secure = fingerprint != nullptr;
  m.health = secure ? aerie::process_status_t::OK : aerie::process_status_t::WARN;
  m.message = secure ? "SECURE key " + std::string(fingerprint) + " epoch " + std::to_string(epoch) +
                           " peer epoch 2; " + half + " half, sends up"
                     : "INSECURE: no key (--insecure), datagrams in the clear and unauthenticated; " +
                           std::string(half) + " half, sends up";
  for (auto [name, value] : {std::pair<const char*, int64_t>{"up.sent", 10}, {"epoch", epoch}, {"peer_epoch", 2},
                             {"secure", secure ? 1 : 0}}) {
    m.counter_names.push_back(name);
    m.counter_values.push_back(value);
  }
  m.ncounters = static_cast<int32_t>(m.counter_names.size());
  m.ntimings = 0;
  return m;
}

aerie::autopilot_state_t autopilot_state(bool signing, int8_t link = aerie::autopilot_state_t::LINK_OK) {
  aerie::autopilot_state_t s{};
  s.utime = util::wall_utime();
  s.seq = 1;
  s.link = link;
  s.autopilot = aerie::autopilot_state_t::AUTOPILOT_PX4;
  s.system_id = 1;
  s.component_id = 1;
  s.armed = true;
  s.mode = "OFFBOARD";
  s.aerie_in_control = true;
  s.signing = signing;
  s.battery_voltage_v = 16.2f;
  s.battery_remaining_pct = 80;
  s.link_quality = 1;
  s.last_command = "MAV_CMD_COMPONENT_ARM_DISARM";
  s.last_result = "ACCEPTED";
  return s;
}

// A deputy's PMD_INFO2 with commands (name, pid: 0 = stopped, run id); sheriff ids 1 for the
// running ones, 2 for the stopped.
struct DeputyCommand {
  const char* name;
  int pid, runid;
};
bot_procman::info2_t deputy_report(const char* host, float cpu_load, const std::vector<DeputyCommand>& cmds,
                                   float cmd_cpu, int64_t cmd_rss) {
  bot_procman::info2_t info{};
  info.utime = util::wall_utime();
  info.host = host;
  info.cpu_load = cpu_load;
  info.phys_mem_total_bytes = 8LL << 30;
  info.phys_mem_free_bytes = 4LL << 30;
  for (const auto& d : cmds) {
    bot_procman::deputy_cmd2_t c{};
    c.cmd.command_name = d.name;
    c.cmd.exec_str = std::string("aerie-") + d.name;
    c.cmd.num_options = 0;
    c.pid = d.pid;
    c.actual_runid = d.runid;
    c.sheriff_id = d.pid ? 1 : 2;
    c.cpu_usage = cmd_cpu;
    c.mem_rss_bytes = cmd_rss;
    info.cmds.push_back(c);
  }
  info.ncmds = static_cast<int32_t>(info.cmds.size());
  info.num_options = 0;
  return info;
}

std::string joined(const std::vector<ProcmanPanel::Line>& lines) {
  std::string s;
  for (const auto& l : lines) s += (l.alarm ? "[red] " : "") + l.text + "\n";
  return s;
}

}  // namespace

TEST_F(Fixture, TrackBoxIsDrawnWhereTheMessageSaysInRed) {
  make();
  publish_image(1000);
  bus.publish("TRACK", box_track(1000, 100, 80, 200, 160));
  aerie::gt_box_t gt{};
  gt.utime = 1000;
  gt.visible = true;
  gt.x = 40;
  gt.y = 30;
  gt.width = 30;
  gt.height = 20;
  bus.publish("GT_TRACK", gt);
  ASSERT_TRUE(render_until([&] { return viewer->image_pane().image_size() == cv::Size(320, 240); }));
  render_until([] { return false; });  // let the overlays arrive
  const cv::Mat img = snapshot();
  const cv::Vec3b red(0, 0, 255), green(0, 255, 0), gray(90, 90, 90);
  // Box edges (left, right, top, bottom midpoints) are red; its centre keeps the image gray.
  for (cv::Point2d p : {cv::Point2d(100, 120), cv::Point2d(200, 120), cv::Point2d(150, 80), cv::Point2d(150, 160)})
    EXPECT_TRUE(near_color(img, window_pixel_of_image(p), red)) << "no red box edge at image " << p;
  EXPECT_TRUE(near_color(img, window_pixel_of_image({150, 120}), gray, 0, 10));
  EXPECT_FALSE(near_color(img, window_pixel_of_image({150, 120}), red, 3));
  // Ground-truth box in green.
  EXPECT_TRUE(near_color(img, window_pixel_of_image({40, 40}), green));
  EXPECT_TRUE(near_color(img, window_pixel_of_image({70, 40}), green));
  EXPECT_FALSE(near_color(img, window_pixel_of_image({55, 40}), green, 2));
  // Disabling the track renderer removes the box.
  viewer->find("track")->set_enabled(false);
  publish_image(2000);
  render_until([] { return false; });
  EXPECT_FALSE(near_color(snapshot(), window_pixel_of_image({100, 120}), red, 2));
}

TEST_F(Fixture, BoxSelectionMapsBackToImageCoordinatesAtAnySizeAndZoom) {
  for (auto [w, h, zoom] : {std::tuple{1280, 800, 1.0}, std::tuple{640, 400, 1.0}, std::tuple{1000, 900, 2.5}}) {
    bus::Bus bus("memq://");  // a bus per window: its subscriptions live as long as that viewer
    struct ResetAtScopeEnd {  // declared after the bus, so the viewer goes first
      std::unique_ptr<Viewer>& v;
      ~ResetAtScopeEnd() { v.reset(); }
    } reset_viewer{viewer};
    viewer = make_viewer(bus, w, h);
    std::vector<aerie::track_cmd_t> cmds;
    bus.subscribe<aerie::track_cmd_t>("TRACK_CMD", [&](const aerie::track_cmd_t& c, const bus::ReceiveInfo&) {
      cmds.push_back(c);
    });
    publish_image_on(bus, 1000);
    ASSERT_TRUE(render_until([&] { return viewer->image_pane().image_size() == cv::Size(320, 240); }));
    viewer->image_pane().zoom(zoom);
    viewer->render_frame();
    // Drag from image (120, 90) to (180, 150) in display coordinates.
    const cv::Point2d a = viewer->image_pane().image_to_display({120, 90});
    const cv::Point2d b = viewer->image_pane().image_to_display({180, 150});
    for (const auto& p : {cv::Point2d(120, 90), cv::Point2d(180, 150), cv::Point2d(160.5, 119.25)}) {
      const auto back = viewer->image_pane().display_to_image(viewer->image_pane().image_to_display(p).x,
                                                              viewer->image_pane().image_to_display(p).y);
      ASSERT_TRUE(back.has_value());
      EXPECT_NEAR(back->x, p.x, 1e-6);
      EXPECT_NEAR(back->y, p.y, 1e-6);
    }
    viewer->begin_selection(a.x, a.y);
    viewer->drag_selection((a.x + b.x) / 2, (a.y + b.y) / 2);
    const auto box = viewer->end_selection(b.x, b.y);
    ASSERT_TRUE(box.has_value()) << w << "x" << h << " zoom " << zoom;
    EXPECT_NEAR(box->x, 120, 1e-6);
    EXPECT_NEAR(box->y, 90, 1e-6);
    EXPECT_NEAR(box->width, 60, 1e-6);
    EXPECT_NEAR(box->height, 60, 1e-6);
    // The viewer's own bus delivers the TRACK_CMD it sent (handled in its LCM thread).
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    viewer->stop();
    ASSERT_EQ(cmds.size(), 1u);
    EXPECT_EQ(cmds[0].command, aerie::track_cmd_t::INIT);
    EXPECT_EQ(cmds[0].tracker, viewer->current_tracker());
    EXPECT_NEAR(cmds[0].x, 120, 1e-6);
  }
}

TEST_F(Fixture, OctomapVoxelsAppearWhereTheMapHasThem) {
  make();
  octomap::OcTree tree(0.2);
  int expected = 0;
  for (int i = 0; i < 5; ++i)  // voxel centres, so no two points share a voxel
    for (int j = 0; j < 5; ++j) {
      tree.updateNode(octomap::point3d(2.1f + 0.2f * i, -0.5f + 0.2f * j, 1.1f), true);
      ++expected;
    }
  publish_map(tree, 5);
  auto* oct = dynamic_cast<OctomapRenderer*>(viewer->find("octomap"));
  ASSERT_NE(oct, nullptr);
  ASSERT_TRUE(render_until([&] { return oct->voxels_shown() > 0; }));
  EXPECT_EQ(oct->voxels_shown(), static_cast<size_t>(expected));
  // Look at the voxels and find coloured (not background, not grid-gray) pixels there.
  auto* scene = viewer->layout().scene.Get();
  scene->ResetCamera();
  const cv::Mat img = snapshot();
  scene->SetWorldPoint(2.5, -0.1, 1.1, 1.0);
  scene->WorldToDisplay();
  double d[3];
  scene->GetDisplayPoint(d);
  const cv::Point p(cvRound(d[0]), img.rows - 1 - cvRound(d[1]));
  const cv::Vec3b c = img.at<cv::Vec3b>(p);
  const int spread = std::max({c[0], c[1], c[2]}) - std::min({c[0], c[1], c[2]});
  EXPECT_GT(spread, 60) << "expected a height-coloured voxel at " << p << ", got " << cv::Mat(c).t();
  // Coarser display resolution: fewer (merged) voxels.
  oct->set_coarsening(2);  // meshed in the renderer's own thread
  ASSERT_TRUE(render_until([&] { return oct->voxels_shown() < static_cast<size_t>(expected); }));
  EXPECT_GT(oct->voxels_shown(), 0u);
  EXPECT_EQ(oct->coarsening_shown(), 2);
}

// Panes are redrawn only when they change: a new camera image redraws the image pane
// while the 3D scene keeps the pixels it had; moving the scene's camera redraws it.
TEST_F(Fixture, UnchangedPanesKeepTheirPixelsAndAreNotRedrawn) {
  make(800, 500);
  octomap::OcTree tree(0.2);
  for (int i = 0; i < 6; ++i) tree.updateNode(octomap::point3d(0.1f + 0.2f * i, 0.1f, 0.1f), true);
  publish_map(tree, 1);
  publish_image(1, 40);
  auto* oct = dynamic_cast<OctomapRenderer*>(viewer->find("octomap"));
  ASSERT_TRUE(render_until([&] { return oct->voxels_shown() > 0 && !viewer->image_pane().image_size().empty(); }));
  for (int i = 0; i < 3; ++i) viewer->render_frame();

  int scene_draws = 0;
  auto count = vtkSmartPointer<vtkCallbackCommand>::New();
  count->SetClientData(&scene_draws);
  count->SetCallback([](vtkObject*, unsigned long, void* n, void*) { ++*static_cast<int*>(n); });
  viewer->layout().scene->AddObserver(vtkCommand::StartEvent, count);
  auto last_frame = [&] {  // the window as last rendered, without rendering again
    auto grab = vtkSmartPointer<vtkWindowToImageFilter>::New();
    grab->SetInput(viewer->layout().window);
    grab->ShouldRerenderOff();
    grab->ReadFrontBufferOff();
    grab->Update();
    int dims[3];
    grab->GetOutput()->GetDimensions(dims);
    cv::Mat rgb(dims[1], dims[0], CV_8UC3, grab->GetOutput()->GetScalarPointer());
    cv::Mat flipped;
    cv::flip(rgb, flipped, 0);  // VTK rows run bottom-up
    return flipped;
  };
  auto viewport = [&](vtkRenderer* r, const cv::Mat& img) {
    double vp[4];
    r->GetViewport(vp);
    const int x0 = cvRound(vp[0] * img.cols), x1 = cvRound(vp[2] * img.cols);
    const int y0 = img.rows - cvRound(vp[3] * img.rows), y1 = img.rows - cvRound(vp[1] * img.rows);
    return img(cv::Rect(x0, y0, x1 - x0, y1 - y0)).clone();
  };
  const cv::Mat before = last_frame();
  const int frames = static_cast<int>(viewer->frames_rendered());
  publish_image(2, 200);
  ASSERT_TRUE(render_until([&] { return viewer->frames_rendered() > frames; }));
  const cv::Mat after = last_frame();
  EXPECT_EQ(scene_draws, 0);
  cv::Mat scene_gray;
  cv::cvtColor(viewport(viewer->layout().scene, after), scene_gray, cv::COLOR_RGB2GRAY);
  double lo = 0, hi = 0;
  cv::minMaxLoc(scene_gray, &lo, &hi);
  EXPECT_GT(hi - lo, 30) << "the kept scene shows the grid and voxels, not a cleared background";
  EXPECT_EQ(cv::norm(viewport(viewer->layout().scene, before), viewport(viewer->layout().scene, after), cv::NORM_INF),
            0);
  EXPECT_GT(cv::norm(viewport(viewer->layout().image, before), viewport(viewer->layout().image, after), cv::NORM_INF),
            100);

  viewer->layout().scene->GetActiveCamera()->Azimuth(40);
  viewer->render_frame();
  EXPECT_EQ(scene_draws, 1);
  EXPECT_GT(cv::norm(viewport(viewer->layout().scene, after), viewport(viewer->layout().scene, last_frame()),
                     cv::NORM_INF),
            0);
}

TEST_F(Fixture, ChartsDrawTheirLines) {
  make();
  for (int i = 0; i < 50; ++i) {
    aerie::control_cmd_t c{};
    c.utime = 1000000 + i * 50000;
    c.seq = i;
    c.heading_deg = static_cast<float>(i);
    c.heading_ref_deg = 90;
    bus.publish("CTRL_CMD", c);
  }
  auto* chart = dynamic_cast<ChartRenderer*>(viewer->find("chart-heading"));
  ASSERT_NE(chart, nullptr);
  ASSERT_TRUE(render_until([&] { return chart->samples_shown() == 50; }));
  const cv::Mat img = snapshot();
  // The heading line colour (BGR 20, 80, 230) appears inside the heading chart's viewport.
  double vp[4];
  viewer->layout().chart(ChartSlot::Heading)->GetViewport(vp);
  const cv::Rect roi(cvRound(vp[0] * img.cols), cvRound((1 - vp[3]) * img.rows), cvRound((vp[2] - vp[0]) * img.cols),
                     cvRound((vp[3] - vp[1]) * img.rows));
  cv::Mat mask;
  cv::inRange(img(roi), cv::Scalar(0, 50, 190), cv::Scalar(60, 120, 255), mask);
  EXPECT_GT(cv::countNonZero(mask), 40);
}

TEST_F(Fixture, SurvivesMalformedMessagesAndChannelsThatStopAndRestart) {
  make();
  const uint8_t junk[5] = {9, 9, 9, 9, 9};
  for (const char* ch : {"CAM_LEFT", "TRACK", "MAP_OCTOMAP", "VO_DEPTH", "CTRL_CMD", "STATUS_X"})
    bus.publish_raw(ch, junk, sizeof(junk));
  aerie::octomap_t bad{};
  bad.resolution = 0.1;
  bad.binary = true;
  bad.data = {1, 2, 3};
  bad.length = 3;
  bus.publish("MAP_OCTOMAP", bad);  // decodes, but is no OctoMap
  auto wrong = image::to_message(cv::Mat(240, 320, CV_8UC1, cv::Scalar(1)), 1, 1);
  wrong.height = 999;  // payload too short for that
  bus.publish("CAM_LEFT", wrong);
  render_until([] { return false; });
  EXPECT_TRUE(viewer->image_pane().image_size().empty());
  // A valid stream afterwards is shown; it stops, and starts again with new content.
  publish_image(10, 50);
  ASSERT_TRUE(render_until([&] { return viewer->image_pane().image_size() == cv::Size(320, 240); }));
  render_until([] { return false; });
  const cv::Point centre = window_pixel_of_image({160, 120});
  EXPECT_TRUE(near_color(snapshot(), centre, {50, 50, 50}, 0, 8));
  publish_image(5000000, 200);
  render_until([] { return false; });
  EXPECT_TRUE(near_color(snapshot(), centre, {200, 200, 200}, 0, 8));
  int64_t malformed = 0;
  for (const auto& s : bus.subscriptions()) malformed += s->counters().malformed + s->counters().handler_errors;
  EXPECT_GE(malformed, 8);
}

TEST_F(Fixture, ProcmanPanelShowsDeputyCommandsAndStartsOrStopsTheSelectedOne) {
  make();
  const bot_procman::info2_t info =
      deputy_report("air", 0.25f, {{"capture", 4242, 1}, {"vo", 0, 0}}, 0.5f, 64LL << 20);
  std::vector<bot_procman::orders2_t> orders;
  bus.subscribe<bot_procman::orders2_t>("PMD_ORDERS2", [&](const bot_procman::orders2_t& o, const bus::ReceiveInfo&) {
    orders.push_back(o);
  });
  bus.publish("PMD_INFO2", info);
  auto* panel = dynamic_cast<ProcmanPanel*>(viewer->find("processes"));
  ASSERT_NE(panel, nullptr);
  ASSERT_TRUE(render_until([&] { return panel->text().find("capture") != std::string::npos; }));
  const std::string text = panel->text();
  EXPECT_NE(text.find("host air"), std::string::npos) << text;
  EXPECT_NE(text.find("capture          running"), std::string::npos) << text;
  EXPECT_NE(text.find("vo"), std::string::npos) << text;

  // Stop the running command (selected first), then start the stopped one.
  auto stop = ProcmanPanel::orders_for(info, 1, false, 5, "v");
  ASSERT_EQ(stop.ncmds, 2);
  EXPECT_EQ(stop.cmds[0].force_quit, 1);
  EXPECT_EQ(stop.cmds[1].force_quit, 0);
  EXPECT_EQ(stop.cmds[1].desired_runid, 0);  // untouched: stays stopped
  auto start = ProcmanPanel::orders_for(info, 2, true, 5, "v");
  EXPECT_EQ(start.cmds[0].desired_runid, 1);  // untouched: keeps running
  EXPECT_EQ(start.cmds[1].desired_runid, 1);  // a new run
  EXPECT_EQ(start.cmds[1].force_quit, 0);

  std::vector<std::vector<uint8_t>> sealed;
  bus.subscribe_raw(procman::kSealedOrdersChannel, [&](const uint8_t* d, size_t n, const bus::ReceiveInfo&) {
    sealed.emplace_back(d, d + n);
  });
  EXPECT_FALSE(panel->keyed());
  EXPECT_NE(panel->text().find("keyed deputies refuse"), std::string::npos) << panel->text();
  viewer->on_key("s");  // the selected command is "capture", running: stop it
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  // With the mission key the same orders go tagged, as a keyed sheriff's, and never plain.
  const seal::SecretKey key = seal::SecretKey::generate();
  panel->use_key(key, 77);
  EXPECT_NE(panel->text().find("keyed orders"), std::string::npos) << panel->text();
  viewer->on_key("s");
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  viewer->stop();
  ASSERT_EQ(orders.size(), 1u);
  EXPECT_EQ(orders[0].host, "air");
  ASSERT_EQ(orders[0].ncmds, 2);
  EXPECT_EQ(orders[0].cmds[0].force_quit, 1);
  ASSERT_EQ(sealed.size(), 1u);
  procman::VerifiedOrders v;
  std::string why;
  ASSERT_EQ(procman::verify_sealed_orders(procman::derive_orders_key(key), sealed[0], v, &why),
            procman::OrdersRefusal::None) << why;
  EXPECT_EQ(v.sender, 77u);
  EXPECT_EQ(v.orders.host, "air");
  EXPECT_EQ(v.orders.cmds[0].force_quit, 1);
}

TEST_F(Fixture, PublishesItsStatusWithTheHeapAndTrimsIt) {
  ViewerOptions o;
  o.offscreen = true;
  o.trim_period_s = 0.2;
  viewer = std::make_unique<Viewer>(bus, o);
  viewer->add_default_renderers();
  std::vector<aerie::process_status_t> statuses;
  bus.subscribe<aerie::process_status_t>("STATUS_VIEWER", [&](const aerie::process_status_t& s, const bus::ReceiveInfo&) {
    statuses.push_back(s);
  });
  viewer->start();
  // Rendered for 3 s: a status a second, a trim every 0.2 s.
  render_until([] { return false; });  // 3 s
  viewer->stop();
  while (bus.handle(0) > 0) {
  }
  ASSERT_GE(statuses.size(), 2u);
  auto counters = [](const aerie::process_status_t& s) {
    std::map<std::string, int64_t> c;
    for (int i = 0; i < s.ncounters; ++i) c[s.counter_names[i]] = s.counter_values[i];
    return c;
  };
  std::map<std::string, int64_t> last = counters(statuses.back());
  EXPECT_EQ(last.count("frames_rendered"), 1u);
#ifndef __SANITIZE_ADDRESS__  // ASan's allocator replaces glibc's heap: mallinfo2 reads zeros
  EXPECT_GT(last["heap_in_use_kb"], 1000);
  EXPECT_GE(last["heap_free_kb"], 0);
  EXPECT_GT(last["rss_kb"], last["heap_in_use_kb"] / 2);
#endif
  // How many trims fit in 3 s depends on how fast the frames come (the trim runs between
  // frames), so the bounds follow from the periods alone: a status comes >= 1 s after the
  // one before and a trim is due 0.2 s after the last, so each status counts at least one
  // trim more than the one before it; and trims come no closer than 0.2 s apart.
  for (size_t k = 1; k < statuses.size(); ++k)
    EXPECT_GT(counters(statuses[k])["heap_trims"], counters(statuses[k - 1])["heap_trims"]) << "status " << k;
  const double span_s = (statuses.back().utime - statuses.front().utime) * 1e-6;
  EXPECT_LE(last["heap_trims"] - counters(statuses.front())["heap_trims"], span_s / o.trim_period_s + 1);
  EXPECT_GE(last["heap_released_kb"], 0);
}

constexpr const char* kFp = "3fa2:1b4c:d5e6:f789";

TEST(PanelAlerts, DoorSecureWhenBothHalvesHaveTheSameKey) {
  const auto air = door_status("air", kFp), ground = door_status("ground", kFp, 4);
  const auto lines = ProcmanPanel::door_lines(&air, 1, &ground, 1);
  ASSERT_EQ(lines.size(), 3u) << joined(lines);
  EXPECT_EQ(lines[0].text, "door: SECURE 3fa2:\u2026 (air and ground agree)");
  EXPECT_EQ(lines[1].text, "  air    SECURE 3fa2:1b4c:d5e6:f789 ep 3");
  EXPECT_EQ(lines[2].text, "  ground SECURE 3fa2:1b4c:d5e6:f789 ep 4");
  for (const auto& l : lines) EXPECT_FALSE(l.alarm) << l.text;
  EXPECT_TRUE(ProcmanPanel::door_lines(nullptr, 0, nullptr, 0).empty());  // no door: no lines
}

TEST(PanelAlerts, DoorInsecureOnEitherHalfIsRed) {
  const auto air = door_status("air", nullptr), ground = door_status("ground", kFp);
  auto lines = ProcmanPanel::door_lines(&air, 1, &ground, 1);
  ASSERT_EQ(lines.size(), 3u) << joined(lines);
  EXPECT_EQ(lines[0].text, "door: INSECURE (air half: no key)");
  EXPECT_TRUE(lines[0].alarm);
  EXPECT_EQ(lines[1].text, "  air    INSECURE");
  EXPECT_TRUE(lines[1].alarm);
  EXPECT_FALSE(lines[2].alarm) << lines[2].text;  // the ground half itself is secure
  const auto ground_insecure = door_status("ground", nullptr);
  lines = ProcmanPanel::door_lines(&air, 1, &ground_insecure, 1);
  EXPECT_EQ(lines[0].text, "door: INSECURE (both halves: no key)");
  lines = ProcmanPanel::door_lines(nullptr, 0, &ground_insecure, 1);
  EXPECT_EQ(lines[0].text, "door: INSECURE (ground half: no key)");
  EXPECT_EQ(lines[1].text, "  air    not heard");
}

TEST(PanelAlerts, DoorFingerprintMismatchIsAnErrorShowingBothFingerprints) {
  const auto air = door_status("air", kFp), ground = door_status("ground", "77aa:0000:1111:2222");
  const auto lines = ProcmanPanel::door_lines(&air, 1, &ground, 1);
  ASSERT_EQ(lines.size(), 3u) << joined(lines);
  EXPECT_EQ(lines[0].text, "door: KEY MISMATCH (air != ground)");
  EXPECT_EQ(lines[1].text, "  air    SECURE 3fa2:1b4c:d5e6:f789 ep 3");
  EXPECT_EQ(lines[2].text, "  ground SECURE 77aa:0000:1111:2222 ep 3");
  for (const auto& l : lines) EXPECT_TRUE(l.alarm) << l.text;
}

TEST(PanelAlerts, DoorHalfHeardAloneOrSilentSaysSo) {
  const auto ground = door_status("ground", kFp);
  auto lines = ProcmanPanel::door_lines(nullptr, 0, &ground, 1);
  ASSERT_EQ(lines.size(), 3u) << joined(lines);
  EXPECT_EQ(lines[0].text, "door: SECURE 3fa2:\u2026 (air not heard)");
  EXPECT_EQ(lines[1].text, "  air    not heard");
  const auto air = door_status("air", kFp);
  lines = ProcmanPanel::door_lines(&air, 12.4, &ground, 1);  // the air half's status stopped crossing
  EXPECT_EQ(lines[1].text, "  air    SECURE 3fa2:1b4c:d5e6:f789 ep 3 silent 12 s");
  EXPECT_TRUE(lines[1].alarm);
  EXPECT_FALSE(lines[2].alarm);
}

TEST(PanelAlerts, AutopilotLinkModeArmingSigningAndLastCommand) {
  using A = aerie::autopilot_state_t;
  auto s = autopilot_state(true);
  auto lines = ProcmanPanel::autopilot_lines(s, 0.5);
  ASSERT_EQ(lines.size(), 3u) << joined(lines);
  EXPECT_EQ(lines[0].text, "autopilot: PX4 OFFBOARD ARMED signed");
  EXPECT_EQ(lines[1].text, "  link OK");
  EXPECT_EQ(lines[2].text, "  COMPONENT_ARM_DISARM: ACCEPTED");
  for (const auto& l : lines) EXPECT_FALSE(l.alarm) << l.text;

  s.signing = false;
  s.link = A::LINK_LOST;
  s.armed = false;
  s.autopilot = A::AUTOPILOT_ARDUPILOT;
  s.mode = "GUIDED";
  s.last_result = "DENIED (Arming denied: not ready)";
  lines = ProcmanPanel::autopilot_lines(s, 0.5);
  ASSERT_EQ(lines.size(), 3u) << joined(lines);
  EXPECT_EQ(lines[0].text, "autopilot: ArduPilot GUIDED disarmed UNSIGNED");
  EXPECT_EQ(lines[1].text, "  link LOST");
  EXPECT_EQ(lines[2].text, "  COMPONENT_ARM_DISARM: DENIED (Arming denied: not ready)");
  for (const auto& l : lines) EXPECT_TRUE(l.alarm) << l.text;

  s = autopilot_state(true);
  s.last_result.clear();
  lines = ProcmanPanel::autopilot_lines(s, 9);  // aerie-mavlink went quiet
  EXPECT_EQ(lines[1].text, "  link OK silent 9 s");
  EXPECT_TRUE(lines[1].alarm);
  EXPECT_EQ(lines[2].text, "  COMPONENT_ARM_DISARM: no answer yet");
  EXPECT_FALSE(lines[2].alarm);
  s.link = A::LINK_NONE;
  s.last_command.clear();
  lines = ProcmanPanel::autopilot_lines(s, 0.5);
  ASSERT_EQ(lines.size(), 1u) << joined(lines);
  EXPECT_EQ(lines[0].text, "autopilot: no heartbeat yet");
}

// Red pixels (the alarm colour) inside the process panel of a snapshot.
int red_pixels_in_panel(const cv::Mat& img, Viewer& v) {
  const double* vp = v.layout().panel->GetViewport();  // x0 y0 x1 y1, normalized, origin bottom-left
  const int w = img.cols, h = img.rows;
  const cv::Rect r(cvRound(vp[0] * w), cvRound((1 - vp[3]) * h), cvRound((vp[2] - vp[0]) * w),
                   cvRound((vp[3] - vp[1]) * h));
  int n = 0;
  for (int y = r.y; y < r.y + r.height; ++y)
    for (int x = r.x; x < r.x + r.width; ++x) {
      const cv::Vec3b c = img.at<cv::Vec3b>(y, x);
      n += c[2] > 200 && c[1] < 110 && c[0] < 110;
    }
  return n;
}

TEST_F(Fixture, PanelShowsTheDoorAndTheAutopilotFromTheirChannelsInRedWhenInsecure) {
  make();
  auto* panel = dynamic_cast<ProcmanPanel*>(viewer->find("processes"));
  ASSERT_NE(panel, nullptr);
  bus.publish("STATUS_LINK_AIR", door_status("air", kFp));
  bus.publish("STATUS_LINK_GROUND", door_status("ground", kFp));
  bus.publish("AUTOPILOT_STATE", autopilot_state(true));
  ASSERT_TRUE(render_until([&] { return panel->alerts().size() == 6; })) << joined(panel->alerts());
  auto lines = panel->alerts();
  EXPECT_EQ(lines[0].text, "door: SECURE 3fa2:\u2026 (air and ground agree)");
  EXPECT_EQ(lines[3].text, "autopilot: PX4 OFFBOARD ARMED signed");
  EXPECT_EQ(lines[4].text, "  link OK");
  EXPECT_EQ(lines[5].text, "  COMPONENT_ARM_DISARM: ACCEPTED");
  viewer->render_frame();
  cv::Mat img = snapshot();
  EXPECT_EQ(red_pixels_in_panel(img, *viewer), 0);
  if (const char* keep = std::getenv("AERIE_VIEWER_KEEP_SNAPSHOT")) cv::imwrite(std::string(keep) + "/secure.png", img);

  bus.publish("STATUS_LINK_AIR", door_status("air", nullptr));  // the air half restarted --insecure
  ASSERT_TRUE(render_until([&] { return panel->alerts()[0].text.find("INSECURE") != std::string::npos; }))
      << joined(panel->alerts());
  lines = panel->alerts();
  EXPECT_EQ(lines[0].text, "door: INSECURE (air half: no key)");
  EXPECT_TRUE(lines[0].alarm);
  EXPECT_FALSE(lines[3].alarm);
  viewer->render_frame();
  img = snapshot();
  EXPECT_GT(red_pixels_in_panel(img, *viewer), 50);
  if (const char* keep = std::getenv("AERIE_VIEWER_KEEP_SNAPSHOT")) cv::imwrite(std::string(keep) + "/insecure.png", img);
  // The door's own status lines are still listed with the other nodes below.
  EXPECT_NE(panel->text().find("link-air"), std::string::npos) << panel->text();
}

// Issue 49: the 't' cycle could not reach eco (aerie-track's default) or dcf, and a drag asked
// for amcmr-ct. It starts with the node's default and holds every tracker of the factory once.
TEST(TrackerCycle, StartsWithTheNodesDefaultAndReachesEveryTracker) {
  const std::vector<std::string> cycle = viewer::tracker_cycle();
  ASSERT_FALSE(cycle.empty());
  EXPECT_EQ(cycle.front(), "eco");
  EXPECT_EQ(cycle.front(), track::kDefaultTracker);
  EXPECT_EQ(viewer::ViewerOptions{}.trackers, cycle);
  std::vector<std::string> every = track::aerie_tracker_names();
  for (const auto& name : track::opencv_tracker_names()) every.push_back(name);
  EXPECT_EQ(cycle.size(), every.size());
  for (const auto& name : every) EXPECT_EQ(std::count(cycle.begin(), cycle.end(), name), 1) << name;
  EXPECT_EQ(std::count(cycle.begin(), cycle.end(), "dcf"), 1);
}

// Issue 49: the process panel's columns were cut at 1280 px. Its text is laid out for the
// width measured in its font: every drawn line fits, long names and messages are abbreviated.
TEST_F(Fixture, ProcessPanelFitsItsPaneAt1280Pixels) {
  make(1280, 800);
  auto* panel = dynamic_cast<ProcmanPanel*>(viewer->find("processes"));
  ASSERT_NE(panel, nullptr);
  bus.publish("PMD_INFO2", deputy_report("companion-computer", 0.5f,
                                         {{"stereo-visual-odometry-front", 4242, 1}, {"capture", 0, 1}}, 1.0f,
                                         1234LL << 20));
  aerie::process_status_t st{};
  st.utime = util::wall_utime();
  st.node = "vo";
  st.health = aerie::process_status_t::WARN;
  st.message = "queue overflowed 12 times in the last second: 3 pairs dropped; sequence gaps 4";
  st.ncounters = st.ntimings = 0;
  bus.publish("STATUS_VO", st);
  bus.publish("STATUS_LINK_AIR", door_status("air", kFp));
  bus.publish("AUTOPILOT_STATE", autopilot_state(true));
  ASSERT_TRUE(render_until([&] { return panel->text().find("vo ") != std::string::npos && panel->alerts().size() >= 3; }))
      << panel->text();
  viewer->render_frame();
  const std::string text = panel->text();
  EXPECT_GE(panel->width_chars(), 40u) << "the panel at 1280 px holds fewer characters than expected";
  EXPECT_GT(panel->room_px(), 250);
  EXPECT_GT(panel->text_width_px(), 100);
  EXPECT_LE(panel->text_width_px(), panel->room_px()) << text;
  // Every line within the measured width; what was too long ends with an ellipsis.
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);)
    EXPECT_EQ(ProcmanPanel::fit(line, panel->width_chars()), line) << line;
  EXPECT_NE(text.find("stereo-visual-od"), std::string::npos) << text;  // abbreviated, still recognisable
  EXPECT_NE(text.find("queue overflowed"), std::string::npos) << text;
  EXPECT_NE(text.find("\u2026"), std::string::npos) << text;
  // fit() counts characters, not bytes, and marks a cut line.
  EXPECT_EQ(ProcmanPanel::fit("abcdef", 4), "abc\u2026");
  EXPECT_EQ(ProcmanPanel::fit("ab\u2026cd", 5), "ab\u2026cd");
  EXPECT_EQ(ProcmanPanel::fit("abcd", 4), "abcd");
}

// Issue 49: the overlay's key list disagreed with docs/viewer.md. The overlay lists every key of
// keys.hpp (test_viewer_frames checks the doc's "Keys" table against it), and the doc's renderer
// numbers are the ones the keys 1-9 toggle.
TEST_F(Fixture, HelpOverlayListsEveryKeyAndTheDocsRendererNumbersAreTheKeys) {
  make();
  const std::string help = viewer->help_text();
  for (const auto& k : kKeys)
    EXPECT_NE(help.find(std::string(k.key) + ": " + std::string(k.overlay)), std::string::npos) << k.key << "\n" << help;
  std::ifstream in(AERIE_SOURCE_DIR "/docs/viewer.md");
  ASSERT_TRUE(in);
  size_t numbered = 0;
  for (std::string line; std::getline(in, line);) {
    if (line.size() < 8 || line[0] != '|' || line[2] < '1' || line[2] > '9' || line[3] != ' ') continue;
    const size_t n = static_cast<size_t>(line[2] - '0'), a = line.find('`'), b = line.find('`', a + 1);
    ASSERT_NE(b, std::string::npos) << line;
    ASSERT_LE(n, viewer->renderers().size());
    EXPECT_EQ(line.substr(a + 1, b - a - 1), viewer->renderers()[n - 1]->name()) << "docs/viewer.md renderer " << n;
    ++numbered;
  }
  EXPECT_EQ(numbered, 9u);
}

// Issue 49: VO's world is the first camera's frame (z forward). With a ground truth, the scene is
// the ground truth's world (z up) and the ground truth is drawn aligned to the estimate.
TEST_F(Fixture, SceneIsGravityAlignedFromTheFirstGroundTruthPoseAndTheGroundTruthAligned) {
  make();
  auto* world = dynamic_cast<WorldFrameRenderer*>(viewer->find("world"));
  ASSERT_NE(world, nullptr);
  EXPECT_EQ(world->gravity(), GravitySource::None);
  // A level camera looking along world x, 1.2 m up, flying a curve; VO starts at identity.
  Eigen::Matrix3d R_w_c0;
  R_w_c0.col(0) = Eigen::Vector3d(0, -1, 0);
  R_w_c0.col(1) = Eigen::Vector3d(0, 0, -1);
  R_w_c0.col(2) = Eigen::Vector3d(1, 0, 0);
  const geometry::SE3 T_w_c0(R_w_c0, Eigen::Vector3d(2, 3, 1.2));
  const int64_t t0 = 1'403'715'273'262'142;  // dataset time
  std::vector<geometry::SE3> gt;
  for (int i = 0; i < 40; ++i) {
    const double s = 0.1 * i;
    gt.push_back(geometry::SE3(Eigen::Matrix3d(Eigen::AngleAxisd(0.2 * s, Eigen::Vector3d::UnitZ())) * R_w_c0,
                               Eigen::Vector3d(2 + s, 3 + 0.5 * std::sin(s), 1.2 + 0.2 * s)));
  }
  for (int i = 0; i < 40; ++i) {
    const int64_t t = t0 + i * 50'000;
    aerie::gt_pose_t g{};
    g.utime = t;
    g.frame_id = "vicon";
    gt[i].to_wxyz(g.orientation);
    for (int k = 0; k < 3; ++k) g.position[k] = gt[i].translation()[k];
    bus.publish("GT_POSE", g);
    const geometry::SE3 vo = T_w_c0.inverse() * gt[i];
    aerie::pose_t p{};
    p.utime = t;
    vo.to_wxyz(p.orientation);
    for (int k = 0; k < 3; ++k) p.position[k] = vo.translation()[k];
    bus.publish("VO_POSE", p);
  }
  // 'g' aligns at once (else every --align-period seconds while poses come).
  ASSERT_TRUE(render_until([&] {
    viewer->on_key("g");
    viewer->render_frame();
    return world->alignment() && world->alignment()->pairs == 40;
  })) << world->label();
  EXPECT_EQ(world->gravity(), GravitySource::FirstGtPose);
  // The estimate drawn where the ground truth is: z up, on the grid.
  const geometry::SE3 vo_last = T_w_c0.inverse() * gt.back();
  EXPECT_LT((world->display_from_vo() * vo_last.translation() - gt.back().translation()).norm(), 1e-9);
  EXPECT_LT((world->display_from_gt() * gt.back().translation() - gt.back().translation()).norm(), 1e-6);
  EXPECT_LT(world->alignment()->ate_m, 1e-6);
  EXPECT_NE(world->label().find("gravity: first GT pose"), std::string::npos) << world->label();
  EXPECT_NE(world->label().find("GT aligned: SE(3), 40 pairs, ATE 0.000 m"), std::string::npos) << world->label();
  // Dataset stamps: the latency chart measures from the frame's arrival, not from 2014.
  auto* latency = dynamic_cast<LatencyChart*>(viewer->find("chart-latency"));
  ASSERT_NE(latency, nullptr);
  aerie::pose_t cam{};
  cam.utime = t0 + 10'000'000;
  cam.orientation[0] = 1;
  bus.publish("CAM_STEREO", cam);
  bus.publish("VO_POSE", cam);
  ASSERT_TRUE(render_until([&] { return latency->source_clock(); }));
}
