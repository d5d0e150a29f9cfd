#!/usr/bin/env python3
# Noeud exam : altitude du drone a partir de la temperature et de la pression,
# publiee sur /altitude a 10 Hz, et voyant ALT WARN via le service /altitude_warning.
import math
import rospy
from std_msgs.msg import Float32
from mydrone.srv import AltitudeWarning

P0 = 101325.0   # pression au niveau de la mer (Pa)
MU = 0.0289644  # masse molaire de l'air (kg/mol)
G = 9.80665     # gravite (m/s^2)
R = 8.31432     # constante des gaz parfaits (J/K.mol)
DELAI = 5.0     # secondes au-dessus du seuil avant l'alerte


class Exam(object):
    """Le noeud sous forme d'objet : les dernieres mesures sont des attributs."""

    def __init__(self):
        self.temperature = None  # degres Celsius
        self.pression = None     # Pa
        self.seuil = rospy.get_param('~seuil', 1300.0)  # seuil d'altitude (m)
        self.depuis = None       # instant du premier passage au-dessus du seuil
        self.alerte = False      # vrai quand le voyant est rouge
        self.pub = rospy.Publisher('altitude', Float32, queue_size=10)
        rospy.wait_for_service('altitude_warning')
        self.voyant = rospy.ServiceProxy('altitude_warning', AltitudeWarning)
        rospy.Subscriber('temperature', Float32, self.cb_temperature)
        rospy.Subscriber('pressure', Float32, self.cb_pression)

    def cb_temperature(self, msg):
        self.temperature = msg.data  # on garde la derniere valeur

    def cb_pression(self, msg):
        self.pression = msg.data     # idem

    def altitude(self):
        # equation (1) resolue en h, T en Kelvin
        return R * (self.temperature + 273.15) / (MU * G) * math.log(P0 / self.pression)

    def tour(self):
        if self.temperature is None or self.pression is None:
            return
        h = self.altitude()
        self.pub.publish(h)
        maintenant = rospy.get_time()
        if h > self.seuil:
            if self.depuis is None:
                self.depuis = maintenant             # debut du depassement
            if not self.alerte and maintenant - self.depuis >= DELAI:
                self.voyant('warning')               # voyant rouge
                self.alerte = True
        else:
            self.depuis = None
            if self.alerte:
                self.voyant('normal')                # retour au vert
                self.alerte = False


if __name__ == '__main__':
    rospy.init_node('exam')
    noeud = Exam()
    frequence = rospy.Rate(10)  # 10 Hz
    while not rospy.is_shutdown():
        noeud.tour()
        frequence.sleep()
