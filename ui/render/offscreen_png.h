#pragma once
// Writing what an offscreen VTK render window shows to a PNG file, for screenshots and plots.

#include <filesystem>
#include <string>

class vtkRenderWindow;

namespace liversim {

// Throws std::runtime_error naming `file` unless an X display is available (VTK aborts the process
// when it cannot open one; Debian's VTK has no EGL or OSMesa) and the file's folder exists.
// `action` says what was asked, e.g. "render" or "plot".
void check_offscreen_png_target(const std::filesystem::path& file, const std::string& action);

// Has an offscreen window not yet drawn talk to the X server through the process's one connection,
// opened at the first call and kept. An X server resets when its last client leaves (Xvfb does,
// unless started with -noreset) and refuses connections meanwhile, and VTK aborts the process when
// a window cannot connect: windows that each opened and closed a connection of their own, one
// after another, raced that reset.
void use_shared_x_connection(vtkRenderWindow* window);

// Renders `window` (on the shared X connection when not yet drawn) and writes its picture to
// `file`; on failure removes any partial file and throws std::runtime_error naming it.
void write_window_png(vtkRenderWindow* window, const std::filesystem::path& file);

}  // namespace liversim
