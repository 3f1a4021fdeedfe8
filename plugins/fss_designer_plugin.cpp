#include "fss_designer_plugin.h"

#include <fss/widgets/quality_panel.h>
#include <fss/widgets/remesh_widget.h>
#include <fss/widgets/scan_panel.h>
#include <fss/widgets/vtk_view.h>

namespace fss::designer {

QString CustomWidget::group() const {
    return QString::fromLatin1(WidgetCollection::kGroup);
}

QString CustomWidget::domXml() const {
    return QStringLiteral(R"(<ui language="c++">
 <widget class="%1" name="%2">
  <property name="geometry"><rect><x>0</x><y>0</y><width>%3</width><height>%4</height></rect></property>
 </widget>
</ui>
)")
        .arg(d_.className, d_.objectName)
        .arg(d_.defaultSize.width())
        .arg(d_.defaultSize.height());
}

WidgetCollection::WidgetCollection(QObject* parent) : QObject(parent) {
    // One line per widget.
    addWidget<widgets::VtkView>({"fss::widgets::VtkView",
                                 "fss/widgets/vtk_view.h",
                                 "vtkView",
                                 "3D view of a triangle mesh (VTK in a QOpenGLWidget)",
                                 "Shows one mesh shaded with its edges, quality colour maps, a ghost of the "
                                 "reference, a preview patch and 2D overlays; trackball navigation.",
                                 {400, 300},
                                 {}});
    addWidget<widgets::RemeshWidget>(
        {"fss::widgets::RemeshWidget",
         "fss/widgets/remesh_widget.h",
         "remeshWidget",
         "Drop-in remeshing widget: view, tools, scan and quality panels, history",
         "Virtual range scanning of a mesh with lasso, scan and fishbone tools, "
         "undo/redo and live quality histograms.",
         {800, 600},
         {}});
    addWidget<widgets::ScanPanel>({"fss::widgets::ScanPanel",
                                   "fss/widgets/scan_panel.h",
                                   "scanPanel",
                                   "Scan settings: resolution, erosion / dilation, thresholds, force-replace",
                                   "The settings of the next scan, with the resulting edge length.",
                                   {240, 320},
                                   {}});
    addWidget<widgets::QualityPanel>({"fss::widgets::QualityPanel",
                                      "fss/widgets/quality_panel.h",
                                      "qualityPanel",
                                      "Valence and minimum-angle histograms of a mesh",
                                      "Histograms of vertex valence and smallest face angle, updated after "
                                      "every accept, undo and redo.",
                                      {240, 320},
                                      {}});
}

QList<QDesignerCustomWidgetInterface*> WidgetCollection::customWidgets() const {
    QList<QDesignerCustomWidgetInterface*> list;
    for (const auto& w : widgets_)
        list.append(w.get());
    return list;
}

} // namespace fss::designer

#include "moc_fss_designer_plugin.cpp" // meta-object code compiled here, as in widgets/ (one parse less)
