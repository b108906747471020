// A user's program on the installed core (volscissors::core): a synthetic disc from the phantom
// generator, a closed live-wire contour around it through three seeds, and its distance to the
// true circle. Exit 0 when every contour pixel is within 1.5 pixels of it.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "phantom/phantom.h"
#include "scissors/live_wire.h"

int main() {
  vs::Shapes2DOptions options;
  options.width = options.height = 96;
  options.shapeCount = 1;  // one disc
  options.seed = 3;
  vs::Shapes2DPhantom phantom = vs::makeShapes2DPhantom(options);
  const vs::Shape2D& disc = phantom.truth.shapes.at(0);

  vs::LiveWire wire = vs::LiveWire::fromImage(vs::AnyVolume(phantom.image));
  auto at = [&](double angle) {
    return wire.snap({std::llround(disc.center.x() + disc.radius * std::cos(angle)),
                      std::llround(disc.center.y() + disc.radius * std::sin(angle))},
                     2.0);
  };
  wire.setSeed(at(0.0));
  wire.commit(at(2.1));
  wire.commit(at(4.2));
  wire.close();
  const vs::LiveWireContour contour = wire.contour();
  double worst = 0;  // largest distance of a contour pixel from the true circle, pixels
  for (const vs::PixelUV& p : contour.pixels)
    worst = std::max(
        worst, std::abs(std::hypot(double(p[0]) - disc.center.x(), double(p[1]) - disc.center.y()) - disc.radius));
  std::printf(
      "volscissors core example: disc radius %.2f px, closed contour of %zu pixels, %.1f mm long, "
      "at most %.2f px from the true circle\n",
      disc.radius, contour.pixels.size(), contour.lengthMm, worst);
  return contour.closed && worst <= 1.5 ? 0 : 1;
}
