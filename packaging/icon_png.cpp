// Build-time tool: renders the SVG icon into the PNG sizes the desktop's icon theme wants
// (hicolor NxN/apps), so the PNGs are made here from the one source rather than kept as binaries.
// Usage: retile-icon-png ICON.svg OUT_DIR SIZE...
#include <QGuiApplication>
#include <QImage>
#include <QPainter>
#include <QSvgRenderer>
#include <cstdio>
#include <cstdlib>

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: retile-icon-png ICON.svg OUT_DIR SIZE...\n");
    return 2;
  }
  qputenv("QT_QPA_PLATFORM", "offscreen");
  QGuiApplication app(argc, argv);
  QSvgRenderer svg(QString::fromLocal8Bit(argv[1]));
  if (!svg.isValid()) {
    std::fprintf(stderr, "error: %s: not a valid SVG\n", argv[1]);
    return 1;
  }
  for (int i = 3; i < argc; ++i) {
    const int size = std::atoi(argv[i]);
    if (size <= 0 || size > 4096) {
      std::fprintf(stderr, "error: size '%s' is not between 1 and 4096\n", argv[i]);
      return 2;
    }
    QImage image(size, size, QImage::Format_ARGB32_Premultiplied);
    image.fill(Qt::transparent);
    QPainter painter(&image);
    painter.setRenderHint(QPainter::Antialiasing);
    svg.render(&painter);
    painter.end();
    const QString out = QStringLiteral("%1/retile-%2.png").arg(QString::fromLocal8Bit(argv[2])).arg(size);
    if (!image.save(out)) {
      std::fprintf(stderr, "error: cannot write %s\n", qPrintable(out));
      return 1;
    }
  }
  return 0;
}
