#include "fss_designer_plugin.h"

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
    // One line per widget. (RemeshWidget and the panels join here.)
    addWidget<widgets::VtkView>({"fss::widgets::VtkView",
                                 "fss/widgets/vtk_view.h",
                                 "vtkView",
                                 "3D view of a triangle mesh (VTK in a QOpenGLWidget)",
                                 "Shows one mesh shaded with its edges, quality colour maps, a ghost of the "
                                 "reference, a preview patch and 2D overlays; trackball navigation.",
                                 {400, 300},
                                 {}});
}

QList<QDesignerCustomWidgetInterface*> WidgetCollection::customWidgets() const {
    QList<QDesignerCustomWidgetInterface*> list;
    for (const auto& w : widgets_)
        list.append(w.get());
    return list;
}

} // namespace fss::designer
