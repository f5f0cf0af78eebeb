// `retile [SCENE]`: the editor. The only place the command line meets Qt.
#include <QApplication>
#include <QCheckBox>
#include <QFileInfo>
#include <QMessageBox>
#include <QPixmap>
#include <QScreen>
#include <QTimer>
#include <QTreeWidget>
#include <QTreeWidgetItemIterator>

#include "cli.h"
#include "main_window.h"
#include "retile/log.h"

namespace retile::cli {

int runEditor(int argc, char** argv, const std::string& file) {
  QApplication app(argc, argv);
  QApplication::setApplicationName("Retile");
  QApplication::setOrganizationName("Retile");
  Scene scene = makeDefaultScene();
  std::filesystem::path path;
  std::vector<std::string> warnings;
  QString openError;
  if (!file.empty() && file != "default") {
    auto loaded = importScene(file);
    if (loaded) {
      scene = std::move(loaded->scene);
      warnings = std::move(loaded->warnings);
      path = file;
    } else {
      // The editor still opens, on the built-in scene, and says why.
      openError = QString::fromStdString(loaded.error());
    }
  }
  QStringList recovery = ui::MainWindow::recoveryCandidates();
  ui::EditorOptions options;
  // The window and its docks as the user left them (a screenshot shows the default layout).
  options.keepLayout = !qEnvironmentVariableIsSet("RETILE_SCREENSHOT");
  if (qEnvironmentVariable("RETILE_SCREENSHOT_FRAMING") == "viewport") options.cameraFraming = false;
  ui::MainWindow window(std::move(scene), path, options);
  window.show();
  if (!path.empty()) window.opened(path, warnings);
  // The last session did not close cleanly: offer its newest autosave.
  if (!recovery.isEmpty() && !qEnvironmentVariableIsSet("RETILE_NO_PROMPTS") &&
      QMessageBox::question(&window, QObject::tr("Recover"),
                            QObject::tr("Retile did not close cleanly last time. Open the autosaved scene from %1?")
                                .arg(QFileInfo(recovery.front()).lastModified().toString())) == QMessageBox::Yes)
    window.openFile(recovery.front().toStdString());
  // scripts/screenshot.sh: converge a little, select and move an object so that the overlays show
  // a pass in progress, then save the whole window and quit.
  if (qEnvironmentVariableIsSet("RETILE_SCREENSHOT")) {
    if (qEnvironmentVariableIsSet("RETILE_SCREENSHOT_DENOISE"))
      if (auto* denoise = window.findChild<QCheckBox*>("denoise")) denoise->setChecked(true);
    auto* timer = new QTimer(&window);
    int settle = qEnvironmentVariableIntValue("RETILE_SCREENSHOT_FRAMES");
    if (settle <= 0) settle = 40;
    QObject::connect(timer, &QTimer::timeout, &window, [&window, settle, stage = 0]() mutable {
      std::uint64_t frames = window.engine()->framesRendered();
      if (stage == 0 && frames >= static_cast<std::uint64_t>(settle)) {
        const QString wanted = qEnvironmentVariable("RETILE_SCREENSHOT_SELECT");
        bool found = false;
        for (const Object& o : window.scene().objects)
          if (o.name == wanted.toStdString()) {
            found = true;
            window.select(o.id);
            Object moved = o;
            moved.transform = Mat4::translate({0.0f, 0.08f, 0.0f}) * o.transform;
            window.edit(SetObject{o}, SetObject{moved}, QObject::tr("Move"));
          }
        // Anything else the outliner lists (a material, the camera, the environment): shown in Properties.
        for (QTreeWidgetItemIterator it(window.outliner()); !found && !wanted.isEmpty() && *it; ++it)
          if ((*it)->text(0) == wanted) {
            found = true;
            window.outliner()->clearSelection();
            (*it)->setSelected(true);
          }
        stage = 1;
      } else if (stage >= 1 && ++stage > 6) {
        // From the X server: QWidget::grab cannot see the Vulkan window's swapchain.
        window.screen()->grabWindow(window.winId()).save(qEnvironmentVariable("RETILE_SCREENSHOT"));
        QApplication::quit();
      }
    });
    timer->start(250);
  }
  if (!openError.isEmpty()) QMessageBox::warning(&window, QObject::tr("Cannot open scene"), openError);
  return QApplication::exec();
}

}  // namespace retile::cli
