// The window's document on disk: opening, saving, the autosave and its recovery, recent files,
// files dropped on the window. GUI thread only, like the rest of MainWindow.
#include <QCloseEvent>
#include <QDateTime>
#include <QDir>
#include <QDragEnterEvent>
#include <QDropEvent>
#include <QFileDialog>
#include <QFileInfo>
#include <QMenu>
#include <QMessageBox>
#include <QMimeData>
#include <QSettings>
#include <QStandardPaths>
#include <QStatusBar>
#include <QTimer>
#include <QUrl>

#include "frame_view.h"
#include "main_window.h"
#include "retile/image.h"
#include "retile/io.h"

namespace retile::ui {

void MainWindow::startAutosave() {
  // Autosave every 5 minutes ($RETILE_AUTOSAVE_SECONDS overrides) to rotating recovery files.
  auto* autosaveTimer = new QTimer(this);
  int every = qEnvironmentVariableIsSet("RETILE_AUTOSAVE_SECONDS") ? qEnvironmentVariableIntValue("RETILE_AUTOSAVE_SECONDS") : 300;
  connect(autosaveTimer, &QTimer::timeout, this, [this] { autosave(); });
  autosaveTimer->start(std::max(1, every) * 1000);
  QDir().mkpath(recoveryDirectory());
  QFile lock(recoveryDirectory() + "/session.lock");
  if (lock.open(QIODevice::WriteOnly)) lock.write(QByteArray::number(QCoreApplication::applicationPid()));
}

QString MainWindow::recoveryDirectory() {
  QString base = qEnvironmentVariable("RETILE_RECOVERY_DIR");
  if (base.isEmpty()) base = QStandardPaths::writableLocation(QStandardPaths::AppDataLocation) + "/recovery";
  return base;
}

QStringList MainWindow::recoveryCandidates() {
  QDir dir(recoveryDirectory());
  if (!dir.exists("session.lock")) return {};  // the last session closed cleanly
  QStringList out;
  for (const QFileInfo& f : dir.entryInfoList({"autosave-*.retile"}, QDir::Files, QDir::Time)) out << f.absoluteFilePath();
  return out;
}

bool MainWindow::autosave() {
  if (undo_.index() == autosavedIndex_ || undo_.isClean()) return false;
  QString file = recoveryDirectory() + QString("/autosave-%1.retile").arg(autosaveSlot_);
  auto r = saveNativeScene(doc_.scene(), file.toStdString());
  if (!r) {
    log(tr("autosave failed: %1").arg(QString::fromStdString(r.error())));
    return false;
  }
  autosaveSlot_ = (autosaveSlot_ + 1) % 3;
  autosavedIndex_ = undo_.index();
  log(tr("autosaved to %1").arg(file));
  return true;
}

void MainWindow::rememberRecent(const std::filesystem::path& file) {
  QSettings settings;
  QStringList recent = settings.value("recentFiles").toStringList();
  QString f = QString::fromStdString(std::filesystem::absolute(file).string());
  recent.removeAll(f);
  recent.prepend(f);
  while (recent.size() > 10) recent.removeLast();
  settings.setValue("recentFiles", recent);
}

void MainWindow::rebuildRecentMenu() {
  recentMenu_->clear();
  QSettings settings;
  for (const QString& f : settings.value("recentFiles").toStringList()) {
    QAction* a = recentMenu_->addAction(f, this, [this, f] {
      if (maybeSave()) openFile(f.toStdString());
    });
    a->setEnabled(QFileInfo::exists(f));  // greyed when the file has gone
  }
  if (recentMenu_->isEmpty()) recentMenu_->addAction(tr("(none yet)"))->setEnabled(false);
}

void MainWindow::dragEnterEvent(QDragEnterEvent* e) {
  if (e->mimeData()->hasUrls()) e->acceptProposedAction();
}

void MainWindow::dropEvent(QDropEvent* e) {
  for (const QUrl& url : e->mimeData()->urls())
    if (url.isLocalFile()) {
      if (!maybeSave()) return;
      openFile(url.toLocalFile().toStdString());
      return;
    }
}

bool MainWindow::openFile(const std::filesystem::path& file) {
  auto r = importScene(file);
  if (!r) {
    showError(tr("Cannot open scene"), QString::fromStdString(r.error()));
    return false;
  }
  replaceDocument(std::move(r->scene), file);
  opened(file, r->warnings);
  return true;
}

void MainWindow::opened(const std::filesystem::path& file, const std::vector<std::string>& warnings) {
  log(tr("opened %1").arg(QString::fromStdString(file.string())));
  rememberRecent(file);
  for (const auto& w : warnings) log(tr("warning: %1").arg(QString::fromStdString(w)));
  importWarnings_ = warnings;
  if (warnings.empty()) return;
  const QString text = tr("%n warning(s) opening %1: see the Log", nullptr, static_cast<int>(warnings.size())).arg(documentName());
  view_->showNotice(text, 8000);
  statusBar()->showMessage(text, 15000);
  auto* logDock = findChild<QDockWidget*>("log");
  if (!logDock) return;
  // Beside the node graph, not over it: a tab raised in front of the graph would hide it until
  // the user went back to it.
  auto* graphDock = findChild<QDockWidget*>("nodeGraphDock");
  // (splitDockWidget would add it to the graph's tabs again: it is taken out of them first.)
  if (graphDock && graphDock->isVisible() && tabifiedDockWidgets(graphDock).contains(logDock)) {
    removeDockWidget(logDock);
    addDockWidget(Qt::BottomDockWidgetArea, logDock, Qt::Horizontal);
  }
  logDock->show();
  logDock->raise();
}

bool MainWindow::maybeSave() {
  if (undo_.isClean() || qEnvironmentVariableIsSet("RETILE_NO_PROMPTS")) return true;
  auto answer = QMessageBox::question(this, tr("Unsaved changes"), tr("Save the changes to the current scene first?"),
                                      QMessageBox::Save | QMessageBox::Discard | QMessageBox::Cancel);
  if (answer == QMessageBox::Cancel) return false;
  if (answer == QMessageBox::Discard) return true;
  std::filesystem::path target = file_;
  if (target.empty() || target.extension() != ".retile") {
    QString f = QFileDialog::getSaveFileName(this, tr("Save scene"), QString(), tr("Retile scenes (*.retile)"));
    if (f.isEmpty()) return false;
    target = f.toStdString();
  }
  return saveTo(target);
}

bool MainWindow::saveAs() {
  QFileDialog dialog(this, tr("Save scene as"), QString::fromStdString(file_.parent_path().string()), tr("Retile scenes (*.retile)"));
  dialog.setObjectName("saveAsDialog");
  dialog.setAcceptMode(QFileDialog::AcceptSave);
  dialog.setDefaultSuffix("retile");
  if (dialog.exec() != QDialog::Accepted || dialog.selectedFiles().isEmpty()) return false;
  return saveTo(dialog.selectedFiles().front().toStdString());
}

bool MainWindow::saveImage() {
  // In the folder of the last image saved, else the scene's, named after the scene.
  const std::filesystem::path folder = !imageFolder_.empty() ? imageFolder_ : file_.parent_path();
  const std::string stem = file_.empty() ? "retile" : file_.stem().string();
  QFileDialog dialog(this, tr("Save image"), QString::fromStdString(folder.string()), tr("OpenEXR, linear (*.exr);;PNG, as shown (*.png)"));
  dialog.setObjectName("saveImageDialog");
  dialog.setAcceptMode(QFileDialog::AcceptSave);
  dialog.setDefaultSuffix("exr");
  dialog.selectFile(QString::fromStdString(stem + ".exr"));
  if (dialog.exec() != QDialog::Accepted || dialog.selectedFiles().isEmpty()) return false;
  return saveImageTo(dialog.selectedFiles().front().toStdString());
}

bool MainWindow::saveImageTo(const std::filesystem::path& file) {
  const auto& frame = view_->frame();
  if (!frame || !frame->image) {
    showError(tr("Cannot save the image"), tr("%1: nothing is rendered yet").arg(QString::fromStdString(file.string())));
    return false;
  }
  // writeRenderImage refuses a name not ending in .exr or .png, saying so.
  auto r = writeRenderImage(*frame->image, file, view_->display());
  if (!r) {
    showError(tr("Cannot save the image"), QString::fromStdString(r.error()));
    return false;
  }
  imageFolder_ = file.parent_path();
  notify(tr("saved the image (%1x%2) to %3").arg(frame->image->width).arg(frame->image->height).arg(QString::fromStdString(file.string())));
  return true;
}

QString MainWindow::documentName() const {
  if (file_.empty()) return tr("the built-in scene");
  const QString name = QString::fromStdString(file_.filename().string());
  const std::string folder = file_.parent_path().filename().string();
  return folder.empty() ? name : tr("%1 (%2)").arg(name, QString::fromStdString(folder));
}

void MainWindow::updateTitle() {
  const QString name = file_.empty() ? tr("built-in scene") : documentName();
  setWindowTitle(tr("%1[*] - Retile").arg(name));
  setWindowModified(!undo_.isClean());
}

bool MainWindow::saveTo(const std::filesystem::path& file) {
  auto r = saveNativeScene(doc_.scene(), file);
  if (!r) {
    showError(tr("Cannot save"), QString::fromStdString(r.error()));
    return false;
  }
  file_ = file;
  undo_.setClean();
  updateTitle();
  rememberRecent(file);
  log(tr("saved %1").arg(QString::fromStdString(file.string())));
  return true;
}

}  // namespace retile::ui
